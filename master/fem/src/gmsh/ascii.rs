//! The ASCII reader: a line cursor that knows file and line numbers, the section loop that
//! dispatches on the `$MeshFormat` version, and the sections both versions share.

use super::build::assemble;
use super::records::{ElemRec, NodeRec};
use super::{GmshError, RawMesh, Result, structure, v22, v41};
use std::collections::{BTreeMap, HashMap};
use std::str::FromStr;

/// Line-by-line reader that knows the file name and line numbers.
pub(super) struct Cursor<'a> {
    pub(super) file: &'a str,
    lines: Vec<&'a str>,
    pos: usize,
}

impl<'a> Cursor<'a> {
    fn new(text: &'a str, file: &'a str) -> Self {
        Cursor { file, lines: text.lines().collect(), pos: 0 }
    }

    /// Next non-blank line with its 1-based number.
    pub(super) fn next(&mut self) -> Option<(usize, &'a str)> {
        while self.pos < self.lines.len() {
            let l = self.lines[self.pos];
            self.pos += 1;
            if !l.trim().is_empty() {
                return Some((self.pos, l));
            }
        }
        None
    }

    pub(super) fn expect(&mut self, what: &str) -> Result<(usize, &'a str)> {
        match self.next() {
            Some(x) => Ok(x),
            None => {
                Err(self
                    .syntax(self.lines.len(), format!("unexpected end of file: expected {what}")))
            }
        }
    }

    /// A line split into fields, for reading one record.
    pub(super) fn fields(&mut self, what: &str) -> Result<Fields<'a>> {
        let (line, text) = self.expect(what)?;
        Ok(Fields { file: self.file, line, toks: text.split_whitespace() })
    }

    pub(super) fn end_section(&mut self, name: &str) -> Result<()> {
        let want = format!("$End{name}");
        let (line, text) = self.expect(&want)?;
        if text.trim() != want {
            return Err(self.syntax(line, format!("expected {want}, found {:?}", text.trim())));
        }
        Ok(())
    }

    pub(super) fn syntax(&self, line: usize, message: String) -> GmshError {
        GmshError::Syntax { file: self.file.to_string(), line, message }
    }
}

/// The whitespace-separated fields of one line, for reading one record.
pub(super) struct Fields<'a> {
    pub(super) file: &'a str,
    pub(super) line: usize,
    pub(super) toks: std::str::SplitWhitespace<'a>,
}

impl Fields<'_> {
    pub(super) fn next<T: FromStr>(&mut self, what: &str) -> Result<T> {
        match self.toks.next() {
            Some(tok) => {
                tok.parse().map_err(|_| self.syntax(format!("expected {what}, found {tok:?}")))
            }
            None => Err(self.syntax(format!("expected {what}, found end of line"))),
        }
    }

    pub(super) fn count(&mut self, what: &str) -> Result<usize> {
        self.next::<usize>(what)
    }

    fn rest(&mut self) -> Vec<&str> {
        self.toks.by_ref().collect()
    }

    pub(super) fn finish(&mut self) -> Result<()> {
        match self.toks.next() {
            None => Ok(()),
            Some(tok) => Err(self.syntax(format!("unexpected extra value {tok:?}"))),
        }
    }

    pub(super) fn syntax(&self, message: String) -> GmshError {
        GmshError::Syntax { file: self.file.to_string(), line: self.line, message }
    }
}

/// The two ASCII versions: the `$MeshFormat` number decides how `$Nodes` and `$Elements`
/// read.
#[derive(Clone, Copy, PartialEq)]
enum Version {
    V2,
    V41,
}

/// Reads an ASCII file section by section; errors name `file`.
pub(super) fn parse_named(text: &str, file: &str) -> Result<RawMesh> {
    let mut cur = Cursor::new(text, file);
    let mut version = None;
    let mut physical_names = BTreeMap::new();
    let mut entities: HashMap<(u32, i32), Vec<i32>> = HashMap::new();
    let mut nodes: Option<Vec<(NodeRec, usize)>> = None;
    let mut elements: Option<Vec<ElemRec>> = None;

    while let Some((line, raw)) = cur.next() {
        let header = raw.trim();
        let Some(name) = header.strip_prefix('$') else {
            return Err(
                cur.syntax(line, format!("expected a section header `$Name`, found {header:?}"))
            );
        };
        if name != "MeshFormat" && version.is_none() {
            return Err(cur.syntax(line, format!("expected $MeshFormat first, found {header:?}")));
        }
        match name {
            "MeshFormat" => {
                let (l, fmt) = cur.expect("the mesh format line")?;
                let t: Vec<&str> = fmt.split_whitespace().collect();
                let unsupported = || GmshError::UnsupportedFormat {
                    file: file.to_string(),
                    line: l,
                    found: fmt.trim().to_string(),
                };
                if t.len() != 3 || t[1] != "0" {
                    return Err(unsupported());
                }
                version = Some(match t[0] {
                    "2" | "2.0" | "2.1" | "2.2" => Version::V2,
                    "4.1" => Version::V41,
                    _ => return Err(unsupported()),
                });
                cur.end_section(name)?;
            }
            "PhysicalNames" => {
                parse_physical_names(&mut cur, &mut physical_names)?;
                cur.end_section(name)?;
            }
            "Entities" => {
                entities = v41::parse_entities(&mut cur)?;
                cur.end_section(name)?;
            }
            "Nodes" => {
                nodes = Some(match version {
                    Some(Version::V41) => v41::parse_nodes(&mut cur)?,
                    _ => v22::parse_nodes(&mut cur)?,
                });
                cur.end_section(name)?;
            }
            "Elements" => {
                elements = Some(match version {
                    Some(Version::V41) => v41::parse_elements(&mut cur, &entities)?,
                    _ => v22::parse_elements(&mut cur)?,
                });
                cur.end_section(name)?;
            }
            _ if name.starts_with("End") => {
                return Err(cur.syntax(line, format!("unexpected {header:?} outside its section")));
            }
            _ => {
                // Sections this reader does not need ($Periodic, $NodeData, ...): skip.
                let want = format!("$End{name}");
                loop {
                    let (_, l) = cur.expect(&want)?;
                    if l.trim() == want {
                        break;
                    }
                }
            }
        }
    }
    if version.is_none() {
        return Err(structure(file, "no $MeshFormat section: not a Gmsh .msh file"));
    }
    let nodes = nodes.ok_or_else(|| structure(file, "no $Nodes section"))?;
    let elements = elements.ok_or_else(|| structure(file, "no $Elements section"))?;
    assemble(file, physical_names, nodes, elements)
}

/// `$PhysicalNames`: a count, then one `dim tag "name"` line per group.
fn parse_physical_names(
    cur: &mut Cursor<'_>,
    names: &mut BTreeMap<(u32, i32), String>,
) -> Result<()> {
    let mut f = cur.fields("the number of physical names")?;
    let n = f.count("the number of physical names")?;
    f.finish()?;
    for _ in 0..n {
        let (line, text) = cur.expect("a physical name `dim tag \"name\"`")?;
        let (key, name) = physical_name_line(cur.file, line, text)?;
        names.insert(key, name);
    }
    Ok(())
}

/// One `$PhysicalNames` line: `dim tag "name"`.
pub(super) fn physical_name_line(
    file: &str,
    line: usize,
    text: &str,
) -> Result<((u32, i32), String)> {
    let mut f = Fields { file, line, toks: text.split_whitespace() };
    let dim: u32 = f.next("a physical dimension")?;
    let tag: i32 = f.next("a physical tag")?;
    let rest = f.rest().join(" ");
    let name = rest
        .strip_prefix('"')
        .and_then(|r| r.strip_suffix('"'))
        .ok_or_else(|| f.syntax(format!("expected a quoted physical name, found {rest:?}")))?;
    Ok(((dim, tag), name.to_string()))
}
