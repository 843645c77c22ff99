//! Helpers shared by the `io_*` tests: a strict little XML parser (well-formedness and a tree
//! to inspect), scratch directories and the test data path.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

/// The committed test meshes (the FE core's, `master/fem/tests/data`).
pub fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../fem/tests/data").join(name)
}

/// A fresh, empty scratch directory for one test, under Cargo's `target/tmp`.
pub fn scratch(test: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("cosdem-io-{test}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// An XML element.
#[derive(Debug, Clone, PartialEq)]
pub struct Element {
    pub name: String,
    pub attrs: Vec<(String, String)>,
    pub children: Vec<Element>,
    pub text: String,
}

impl Element {
    pub fn attr(&self, name: &str) -> Option<&str> {
        self.attrs.iter().find(|(k, _)| k == name).map(|(_, v)| v.as_str())
    }

    /// The single child named `name`.
    pub fn child(&self, name: &str) -> &Element {
        let found: Vec<&Element> = self.children.iter().filter(|c| c.name == name).collect();
        assert_eq!(found.len(), 1, "expected one <{name}> in <{}>", self.name);
        found[0]
    }

    /// The `DataArray` child with attribute `Name` = `name`.
    pub fn array(&self, name: &str) -> &Element {
        self.children
            .iter()
            .find(|c| c.name == "DataArray" && c.attr("Name") == Some(name))
            .unwrap_or_else(|| panic!("no DataArray {name:?} in <{}>", self.name))
    }

    /// The whitespace-separated numbers of the element's text.
    pub fn numbers(&self) -> Vec<f64> {
        self.text.split_whitespace().map(|t| t.parse().unwrap()).collect()
    }
}

/// Parses a whole XML document strictly: one optional `<?xml ...?>` declaration, one root
/// element, matching tags, quoted and unique attributes, known entities only.
pub fn parse(doc: &str) -> Result<Element, String> {
    let mut p = Parser { s: doc.as_bytes(), i: 0 };
    p.skip_ws();
    if p.starts("<?xml") {
        let end = p.find("?>").ok_or("unterminated XML declaration")?;
        p.i = end + 2;
    }
    p.skip_ws();
    let root = p.element()?;
    p.skip_ws();
    if p.i != p.s.len() {
        return Err(format!("content after the root element at byte {}", p.i));
    }
    Ok(root)
}

struct Parser<'a> {
    s: &'a [u8],
    i: usize,
}

impl Parser<'_> {
    fn starts(&self, pat: &str) -> bool {
        self.s[self.i..].starts_with(pat.as_bytes())
    }

    fn find(&self, pat: &str) -> Option<usize> {
        let pat = pat.as_bytes();
        (self.i..=self.s.len().saturating_sub(pat.len())).find(|&k| self.s[k..].starts_with(pat))
    }

    fn skip_ws(&mut self) {
        while self.i < self.s.len() && self.s[self.i].is_ascii_whitespace() {
            self.i += 1;
        }
    }

    fn name(&mut self) -> Result<String, String> {
        let start = self.i;
        while self.i < self.s.len()
            && (self.s[self.i].is_ascii_alphanumeric() || b"_-:.".contains(&self.s[self.i]))
        {
            self.i += 1;
        }
        if start == self.i {
            return Err(format!("expected a name at byte {start}"));
        }
        Ok(String::from_utf8(self.s[start..self.i].to_vec()).unwrap())
    }

    fn element(&mut self) -> Result<Element, String> {
        if !self.starts("<") {
            return Err(format!("expected '<' at byte {}", self.i));
        }
        self.i += 1;
        let name = self.name()?;
        let mut attrs: Vec<(String, String)> = Vec::new();
        loop {
            let before = self.i;
            self.skip_ws();
            if self.starts("/>") {
                self.i += 2;
                return Ok(Element { name, attrs, children: vec![], text: String::new() });
            }
            if self.starts(">") {
                self.i += 1;
                break;
            }
            if before == self.i {
                return Err(format!("expected whitespace before an attribute at byte {}", self.i));
            }
            let key = self.name()?;
            if !self.starts("=\"") {
                return Err(format!("attribute {key} is not `=\"...\"` at byte {}", self.i));
            }
            self.i += 2;
            let end = self.find("\"").ok_or("unterminated attribute")?;
            let raw = std::str::from_utf8(&self.s[self.i..end]).unwrap();
            if raw.contains('<') {
                return Err(format!("'<' in attribute {key}"));
            }
            let value = unescape(raw)?;
            self.i = end + 1;
            if attrs.iter().any(|(k, _)| *k == key) {
                return Err(format!("duplicate attribute {key} in <{name}>"));
            }
            attrs.push((key, value));
        }
        let mut children = Vec::new();
        let mut text = String::new();
        loop {
            if self.i >= self.s.len() {
                return Err(format!("<{name}> is never closed"));
            }
            if self.starts("</") {
                self.i += 2;
                let close = self.name()?;
                if close != name {
                    return Err(format!("<{name}> closed by </{close}>"));
                }
                self.skip_ws();
                if !self.starts(">") {
                    return Err(format!("bad closing tag </{close}"));
                }
                self.i += 1;
                return Ok(Element { name, attrs, children, text: unescape(&text)? });
            }
            if self.starts("<") {
                children.push(self.element()?);
            } else {
                text.push(self.s[self.i] as char);
                self.i += 1;
            }
        }
    }
}

fn unescape(raw: &str) -> Result<String, String> {
    let mut out = String::new();
    let mut rest = raw;
    while let Some(k) = rest.find('&') {
        out.push_str(&rest[..k]);
        let end = rest[k..].find(';').ok_or_else(|| format!("unterminated entity in {raw:?}"))?;
        let entity = &rest[k + 1..k + end];
        match entity {
            "amp" => out.push('&'),
            "lt" => out.push('<'),
            "gt" => out.push('>'),
            "quot" => out.push('"'),
            "apos" => out.push('\''),
            e if e.starts_with('#') => {
                let code: u32 = e[1..].parse().map_err(|_| format!("bad entity &{e};"))?;
                out.push(char::from_u32(code).ok_or("bad character reference")?);
            }
            e => return Err(format!("unknown entity &{e};")),
        }
        rest = &rest[k + end + 1..];
    }
    out.push_str(rest);
    Ok(out)
}

#[test]
fn checker_rejects_malformed_xml() {
    assert!(parse("<a><b/></a>").is_ok());
    // Each is refused for its own fault, named.
    for (doc, why) in [
        ("<a><b></a>", "<b> closed by </a>"),
        ("<a x=\"1\" x=\"2\"/>", "duplicate attribute x in <a>"),
        ("<a x=1/>", "attribute x is not `=\"...\"`"),
        ("<a>&nope;</a>", "unknown entity &nope;"),
        ("<a/><b/>", "content after the root element"),
    ] {
        let err = parse(doc).unwrap_err();
        assert!(err.contains(why), "{doc}: {err}");
    }
    assert_eq!(parse("<a k=\"&lt;&amp;\">1 2</a>").unwrap().attr("k"), Some("<&"));
}

/// Decodes standard base64 with padding.
pub fn base64_decode(text: &str) -> Vec<u8> {
    let value = |c: u8| -> u32 {
        match c {
            b'A'..=b'Z' => (c - b'A') as u32,
            b'a'..=b'z' => (c - b'a' + 26) as u32,
            b'0'..=b'9' => (c - b'0' + 52) as u32,
            b'+' => 62,
            b'/' => 63,
            _ => panic!("bad base64 character {c}"),
        }
    };
    let t: Vec<u8> = text.bytes().filter(|c| !c.is_ascii_whitespace()).collect();
    assert_eq!(t.len() % 4, 0, "base64 length");
    let mut out = Vec::new();
    for q in t.chunks(4) {
        let pad = q.iter().filter(|&&c| c == b'=').count();
        let n = q.iter().take(4 - pad).fold(0u32, |n, &c| (n << 6) | value(c)) << (6 * pad);
        out.extend_from_slice(&n.to_be_bytes()[1..4 - pad]);
    }
    out
}

/// The values of a `format="binary"` VTK array: a UInt64 byte count, then the data.
pub fn binary_array(array: &Element, width: usize) -> Vec<Vec<u8>> {
    assert_eq!(array.attr("format"), Some("binary"));
    let bytes = base64_decode(&array.text);
    let len = u64::from_le_bytes(bytes[..8].try_into().unwrap()) as usize;
    assert_eq!(len, bytes.len() - 8, "header byte count");
    bytes[8..].chunks(width).map(|c| c.to_vec()).collect()
}
