//! A job given as a table instead of a file (the Python package's `cosdem.Job(dict)`): written
//! out as TOML text and read by the file's own parser, so that the schema, the defaults and
//! every validation message are the file's. A parse error's line and column point into that
//! generated text, which the user never saw: they are replaced by the key path of the line
//! (`mesh.nz`, `loading.pressure[1].value`).

use crate::schema::Job;
use cosdem_fem::error::{Error, Result};

impl Job {
    /// Reads a job from a TOML table (`origin` names it in errors, e.g. `job dict`). The
    /// table is written out as TOML text (tables as `[headers]`, one key per line) and read
    /// exactly as [`Job::from_toml`] reads a file; a parse error names the key path of the
    /// line it points at instead of a line and column. Relative paths are relative to the
    /// working directory. Returns the job and the text it was read from (what a run
    /// directory keeps as `job.toml`).
    pub fn from_table(table: &toml::Table, origin: &str) -> Result<(Self, String)> {
        let text = toml::to_string(table).map_err(|e| Error::JobFile {
            file: origin.to_string(),
            message: format!("cannot be written as TOML: {e}"),
        })?;
        match Job::from_toml(&text, origin) {
            Ok(job) => Ok((job, text)),
            Err(Error::JobFile { file, message }) => {
                Err(Error::JobFile { file, message: at_key(&text, &message) })
            }
            Err(e) => Err(e),
        }
    }
}

/// Reads any part of a job (e.g. an `AssemblySpec`, the Python package's
/// `cosdem.Assembly(dict)`) from a TOML table, as [`Job::from_table`] reads a whole job: a
/// parse error names `origin` and the key path instead of a line and column.
pub fn from_table<T: serde::de::DeserializeOwned>(table: &toml::Table, origin: &str) -> Result<T> {
    let err = |message: String| Error::JobFile { file: origin.to_string(), message };
    let text =
        toml::to_string(table).map_err(|e| err(format!("cannot be written as TOML: {e}")))?;
    toml::from_str(&text).map_err(|e| err(at_key(&text, &e.to_string())))
}

/// `message` of the TOML parser with its position (`... at line L, column C` and the source
/// excerpt under it) replaced by the key path of line `L` of `text`; the message unchanged
/// when it names no line.
fn at_key(text: &str, message: &str) -> String {
    let Some(line) = error_line(message) else { return message.to_string() };
    let reason = message
        .lines()
        .rev()
        .find(|l| {
            let t = l.trim_start();
            !(t.is_empty() || t.starts_with('|') || t.starts_with(|c: char| c.is_ascii_digit()))
        })
        .unwrap_or(message)
        .trim();
    match key_path(text, line) {
        Some(path) => format!("at key `{path}`: {reason}"),
        None => reason.to_string(),
    }
}

/// The line number of the parser's `line L, column C`.
fn error_line(message: &str) -> Option<usize> {
    let rest = &message[message.find("line ")? + 5..];
    let digits: String = rest.chars().take_while(char::is_ascii_digit).collect();
    digits.parse().ok()
}

/// The dotted key path of 1-based line `line` of `text`: the last table header above it
/// (with each array-of-tables element numbered from 0) and the line's own key. `None` past
/// the end or on a line that is neither.
fn key_path(text: &str, line: usize) -> Option<String> {
    let mut table = String::new();
    let mut elements: std::collections::BTreeMap<String, usize> = Default::default();
    for (i, l) in text.lines().enumerate() {
        let t = l.trim();
        let header = if let Some(h) = t.strip_prefix("[[").and_then(|h| h.strip_suffix("]]")) {
            let h = h.trim().to_string();
            let n = elements.entry(h.clone()).and_modify(|n| *n += 1).or_insert(0);
            Some(format!("{h}[{n}]"))
        } else {
            t.strip_prefix('[').and_then(|h| h.strip_suffix(']')).map(|h| h.trim().to_string())
        };
        if i + 1 == line {
            return match header {
                Some(h) => Some(h),
                None => {
                    let key = t.split('=').next()?.trim().trim_matches('"');
                    Some(if table.is_empty() { key.to_string() } else { format!("{table}.{key}") })
                }
            };
        }
        if let Some(h) = header {
            table = h;
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use crate::{Job, fixtures};

    fn table(name: &str) -> toml::Table {
        toml::from_str(&fixtures::text(name)).unwrap()
    }

    /// A table read back gives the job its file gives: the same schema and defaults.
    #[test]
    fn a_table_gives_the_job_of_its_file() {
        let from_file = fixtures::load("elastic-panel");
        let (from_table, text) = Job::from_table(&table("elastic-panel"), "job dict").unwrap();
        assert_eq!(format!("{from_table:?}"), format!("{from_file:?}"));
        assert!(text.contains("[mesh]"), "{text}");
    }

    /// Unknown keys and wrong types name the key path (the generated text's line and column
    /// would mean nothing to the caller) and the parser's reason.
    #[test]
    fn parse_errors_name_the_key_path() {
        let mut t = table("elastic-panel");
        t["mesh"].as_table_mut().unwrap().insert("nz".into(), 3.into());
        let e = Job::from_table(&t, "job dict").unwrap_err().to_string();
        assert!(e.starts_with("job file job dict: at key `mesh.nz`: unknown field `nz`"), "{e}");
        assert!(!e.contains("line"), "{e}");

        let mut t = table("elastic-panel");
        t["mesh"].as_table_mut().unwrap().insert("nx".into(), "two".into());
        let e = Job::from_table(&t, "job dict").unwrap_err().to_string();
        assert!(e.contains("at key `mesh.nx`") && e.contains("invalid type"), "{e}");
    }

    /// Validation errors are the file's (they already name the key), unchanged.
    #[test]
    fn validation_errors_are_the_files() {
        let mut t = table("elastic-panel");
        t["mesh"].as_table_mut().unwrap().insert("nx".into(), 0.into());
        let from_table = Job::from_table(&t, "job dict").unwrap_err().to_string();
        let text = toml::to_string(&t).unwrap();
        let from_text = Job::from_toml(&text, "job dict").unwrap_err().to_string();
        assert_eq!(from_table, from_text);
        assert!(from_table.contains("mesh.nx"), "{from_table}");
    }

    /// A part of a job reads from its table alone, with the same key paths in its errors.
    #[test]
    fn a_part_reads_from_its_table() {
        let t = table("dem-one-element");
        let assembly = t["material"]["assembly"].as_table().unwrap().clone();
        let spec: cosdem_dem::AssemblySpec = super::from_table(&assembly, "spec").unwrap();
        let material = fixtures::load("dem-one-element").material;
        let crate::MaterialSection::Dem { assembly: from_file } = material else {
            panic!("dem-one-element is a DEM job")
        };
        assert_eq!(spec, *from_file);
        let mut bad = assembly.clone();
        let contact: toml::Table = toml::from_str("kn = 1.0").unwrap();
        bad.insert("contact".into(), contact.into());
        let e = super::from_table::<cosdem_dem::AssemblySpec>(&bad, "spec").unwrap_err();
        assert!(e.to_string().contains("at key `contact.kn`: unknown field `kn`"), "{e}");
    }

    /// Elements of an array of tables are numbered from 0 in the path.
    #[test]
    fn array_of_tables_elements_are_numbered() {
        let text = "a = 1\n[m]\nx = 2\n[[p]]\nv = 1\n[[p]]\nv = 2\nw = 3\n";
        assert_eq!(super::key_path(text, 1).as_deref(), Some("a"));
        assert_eq!(super::key_path(text, 3).as_deref(), Some("m.x"));
        assert_eq!(super::key_path(text, 5).as_deref(), Some("p[0].v"));
        assert_eq!(super::key_path(text, 8).as_deref(), Some("p[1].w"));
        assert_eq!(super::key_path(text, 6).as_deref(), Some("p[1]"));
        assert_eq!(super::key_path(text, 99), None);
    }
}
