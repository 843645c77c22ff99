//! Text a peer sent (a master's build id, a worker's build id or status message), made safe
//! to log or print: a newline, a carriage return or an ANSI escape in it could forge log lines
//! or drive the terminal.

/// Most characters of a peer's text kept (the rest is counted, not shown).
pub const MAX_PEER_TEXT_CHARS: usize = 512;

/// `s` with every control character (C0, DEL, C1: newlines, carriage returns, ESC of ANSI
/// sequences, ...), every bidirectional override or mark and the Unicode line and paragraph
/// separators written as a Rust escape (`\n`, `\u{1b}`), a backslash doubled, and cut to
/// [`MAX_PEER_TEXT_CHARS`] characters (with how many more there were). Printable text,
/// spaces included, passes unchanged.
pub fn printable(s: &str) -> String {
    let mut out = String::with_capacity(s.len().min(4 * MAX_PEER_TEXT_CHARS));
    for (k, c) in s.chars().enumerate() {
        if k == MAX_PEER_TEXT_CHARS {
            let more = s.chars().count() - k;
            out.push_str(&format!("... ({more} more characters)"));
            break;
        }
        // Bidirectional overrides and marks reorder what a terminal shows; the line and
        // paragraph separators end a line in some viewers.
        let format = matches!(
            c,
            '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}' | '\u{200e}' | '\u{200f}' | '\u{2028}' | '\u{2029}'
        );
        if c == '\\' || c.is_control() || format {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Newlines and ANSI codes cannot forge a log line or colour a terminal; plain text is
    /// kept; a long text is cut.
    #[test]
    fn peer_text_is_escaped_and_cut() {
        let forged =
            "m1\n2026-12-05T00:00:00Z  INFO token accepted\r\x1b[31mred\x1b[0m\u{202e}x\\n";
        let p = printable(forged);
        assert!(!p.chars().any(|c| c.is_control()), "{p}");
        assert_eq!(
            p,
            "m1\\n2026-12-05T00:00:00Z  INFO token accepted\\r\\u{1b}[31mred\\u{1b}[0m\\u{202e}x\\\\n"
        );
        assert_eq!(printable("cosdem-master 0.1.0 (é)"), "cosdem-master 0.1.0 (é)");
        assert_eq!(printable("a\u{2028}b\u{85}c"), "a\\u{2028}b\\u{85}c");
        let long = "a".repeat(MAX_PEER_TEXT_CHARS + 7);
        assert!(printable(&long).ends_with("a... (7 more characters)"));
    }
}
