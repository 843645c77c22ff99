//! Binary format 4.1: the same sections as ASCII, with the numbers stored as raw `int`
//! (4 bytes), `size_t` (8 bytes) and `double` (8 bytes) in the writer's byte order.

use super::ascii::{Fields, physical_name_line};
use super::build::assemble;
use super::records::{ElemRec, NodeRec, check_planar, type_info};
use super::{GmshError, RawMesh, Result, structure};
use std::collections::{BTreeMap, HashMap};

/// A byte cursor over a binary file that knows the file name and counts lines for errors.
struct Bin<'a> {
    file: &'a str,
    d: &'a [u8],
    pos: usize,
    big_endian: bool,
    /// (position, line there): line numbers are counted incrementally.
    seen: std::cell::Cell<(usize, usize)>,
}

impl<'a> Bin<'a> {
    /// Line number of the current position (counting newline bytes, also inside binary
    /// data), for error messages that also give the byte offset.
    fn line(&self) -> usize {
        let pos = self.pos.min(self.d.len());
        let (mut p, mut l) = self.seen.get();
        if pos < p {
            (p, l) = (0, 1);
        }
        l += self.d[p..pos].iter().filter(|&&b| b == b'\n').count();
        self.seen.set((pos, l));
        l
    }

    fn err(&self, message: String) -> GmshError {
        GmshError::Syntax {
            file: self.file.to_string(),
            line: self.line(),
            message: format!("at byte {}: {message}", self.pos),
        }
    }

    /// The next non-empty text line, without its newline.
    fn text_line(&mut self, what: &str) -> Result<(usize, &'a str)> {
        loop {
            if self.pos >= self.d.len() {
                return Err(self.err(format!("unexpected end of file: expected {what}")));
            }
            let line = self.line();
            let rest = &self.d[self.pos..];
            let len = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
            let raw = &rest[..len];
            let text = std::str::from_utf8(raw)
                .map_err(|_| self.err(format!("expected {what} as text")))?;
            self.pos += (len + 1).min(rest.len());
            if !text.trim().is_empty() {
                return Ok((line, text.trim()));
            }
        }
    }

    fn take<const N: usize>(&mut self, what: &str) -> Result<[u8; N]> {
        let Some(bytes) = self.d.get(self.pos..self.pos + N) else {
            return Err(self.err(format!("unexpected end of file: expected {what}")));
        };
        self.pos += N;
        Ok(bytes.try_into().expect("slice of length N"))
    }

    fn int(&mut self, what: &str) -> Result<i32> {
        let b = self.take::<4>(what)?;
        Ok(if self.big_endian { i32::from_be_bytes(b) } else { i32::from_le_bytes(b) })
    }

    fn size(&mut self, what: &str) -> Result<u64> {
        let b = self.take::<8>(what)?;
        Ok(if self.big_endian { u64::from_be_bytes(b) } else { u64::from_le_bytes(b) })
    }

    fn double(&mut self, what: &str) -> Result<f64> {
        let b = self.take::<8>(what)?;
        Ok(if self.big_endian { f64::from_be_bytes(b) } else { f64::from_le_bytes(b) })
    }

    /// A count that must fit in the rest of the file at `min_bytes` per item.
    fn count(&mut self, what: &str, min_bytes: usize) -> Result<usize> {
        let at = self.pos;
        let n = self.size(what)?;
        let room = (self.d.len() - self.pos) / min_bytes.max(1);
        if n > room as u64 {
            self.pos = at;
            return Err(self.err(format!("{what} {n} does not fit in the rest of the file")));
        }
        Ok(n as usize)
    }

    fn small_int(&mut self, what: &str, max: i32) -> Result<u32> {
        let v = self.int(what)?;
        if !(0..=max).contains(&v) {
            self.pos -= 4;
            return Err(self.err(format!("expected {what} in 0..={max}, found {v}")));
        }
        Ok(v as u32)
    }

    fn end_section(&mut self, name: &str) -> Result<()> {
        let want = format!("$End{name}");
        let (line, text) = self.text_line(&want)?;
        if text != want {
            return Err(GmshError::Syntax {
                file: self.file.to_string(),
                line,
                message: format!("expected {want}, found {text:?}"),
            });
        }
        Ok(())
    }
}

/// Reads a binary 4.1 file; errors name `file`, the line and the byte offset.
pub(super) fn parse(d: &[u8], file: &str) -> Result<RawMesh> {
    let mut b = Bin { file, d, pos: 0, big_endian: false, seen: std::cell::Cell::new((0, 1)) };
    b.text_line("$MeshFormat")?;
    b.text_line("the mesh format line")?;
    let one = b.take::<4>("the binary endianness marker")?;
    b.big_endian = match one {
        [1, 0, 0, 0] => false,
        [0, 0, 0, 1] => true,
        _ => {
            return Err(
                b.err(format!("expected the integer 1 as endianness marker, found {one:?}"))
            );
        }
    };
    b.end_section("MeshFormat")?;

    let mut physical_names = BTreeMap::new();
    let mut entities: HashMap<(u32, i32), Vec<i32>> = HashMap::new();
    let mut nodes = None;
    let mut elements = None;
    while b.pos < d.len() {
        if d[b.pos..].iter().all(|c| c.is_ascii_whitespace()) {
            break;
        }
        let (line, header) = b.text_line("a section header")?;
        let Some(name) = header.strip_prefix('$') else {
            return Err(GmshError::Syntax {
                file: file.to_string(),
                line,
                message: format!("expected a section header `$Name`, found {header:?}"),
            });
        };
        match name {
            "PhysicalNames" => {
                let (line, text) = b.text_line("the number of physical names")?;
                let mut f = Fields { file, line, toks: text.split_whitespace() };
                let n = f.count("the number of physical names")?;
                f.finish()?;
                for _ in 0..n {
                    let (line, text) = b.text_line("a physical name")?;
                    let (key, name) = physical_name_line(file, line, text)?;
                    physical_names.insert(key, name);
                }
            }
            "Entities" => entities = read_entities(&mut b)?,
            "Nodes" => nodes = Some(read_nodes(&mut b)?),
            "Elements" => elements = Some(read_elements(&mut b, &entities)?),
            _ => {
                // Skip an unneeded section by searching for its end marker.
                let want = format!("\n$End{name}");
                let rest = &d[b.pos.saturating_sub(1)..];
                let Some(k) = rest.windows(want.len()).position(|w| w == want.as_bytes()) else {
                    return Err(b.err(format!("unexpected end of file: expected {}", &want[1..])));
                };
                b.pos = b.pos.saturating_sub(1) + k;
            }
        }
        b.end_section(name)?;
    }
    let nodes = nodes.ok_or_else(|| structure(file, "no $Nodes section"))?;
    let elements = elements.ok_or_else(|| structure(file, "no $Elements section"))?;
    assemble(file, physical_names, nodes, elements)
}

/// `$Entities`: (dimension, entity tag) -> physical tags.
fn read_entities(b: &mut Bin<'_>) -> Result<HashMap<(u32, i32), Vec<i32>>> {
    let mut counts = [0; 4];
    for (dim, c) in counts.iter_mut().enumerate() {
        *c = b.count(&format!("the number of {dim}D entities"), 36)?;
    }
    let mut out = HashMap::new();
    for (dim, &n) in counts.iter().enumerate() {
        for _ in 0..n {
            let tag = b.int("an entity tag")?;
            for _ in 0..if dim == 0 { 3 } else { 6 } {
                b.double("an entity coordinate")?;
            }
            let n_phys = b.count("the number of physical tags", 4)?;
            let mut phys = Vec::with_capacity(n_phys);
            for _ in 0..n_phys {
                phys.push(b.int("a physical tag")?);
            }
            if dim > 0 {
                let n_bound = b.count("the number of bounding entities", 4)?;
                for _ in 0..n_bound {
                    b.int("a bounding entity tag")?;
                }
            }
            out.insert((dim as u32, tag), phys);
        }
    }
    Ok(out)
}

/// `$Nodes`: entity blocks of node tags followed by their coordinates.
fn read_nodes(b: &mut Bin<'_>) -> Result<Vec<(NodeRec, usize)>> {
    let n_blocks = b.count("the number of node blocks", 20)?;
    let n_nodes = b.count("the number of nodes", 32)?;
    b.size("the minimum node tag")?;
    b.size("the maximum node tag")?;
    let mut out = Vec::with_capacity(n_nodes);
    for _ in 0..n_blocks {
        let dim = b.small_int("an entity dimension", 3)?;
        b.int("an entity tag")?;
        let parametric = b.small_int("the parametric flag", 1)?;
        let n = b.count("the number of nodes in the block", 32)?;
        let mut tags = Vec::with_capacity(n);
        for _ in 0..n {
            tags.push(b.size("a node tag")?);
        }
        let extra = if parametric == 1 { dim as usize } else { 0 };
        for tag in tags {
            let line = b.line();
            let x = b.double("a node x coordinate")?;
            let y = b.double("a node y coordinate")?;
            let z = b.double("a node z coordinate")?;
            for _ in 0..extra {
                b.double("a parametric coordinate")?;
            }
            check_planar(b.file, line, tag, x, y, z)?;
            out.push((NodeRec { tag, xy: [x, y] }, line));
        }
    }
    if out.len() != n_nodes {
        return Err(
            b.err(format!("header declares {n_nodes} nodes, the blocks hold {}", out.len()))
        );
    }
    Ok(out)
}

/// `$Elements`: entity blocks of element tags and nodes; the node count comes from the type.
fn read_elements(
    b: &mut Bin<'_>,
    entities: &HashMap<(u32, i32), Vec<i32>>,
) -> Result<Vec<ElemRec>> {
    let n_blocks = b.count("the number of element blocks", 20)?;
    let n_elements = b.count("the number of elements", 16)?;
    b.size("the minimum element tag")?;
    b.size("the maximum element tag")?;
    let mut out = Vec::with_capacity(n_elements);
    for _ in 0..n_blocks {
        let dim = b.small_int("an entity dimension", 3)?;
        let entity = b.int("an entity tag")?;
        let at = b.pos;
        let gmsh_type = b.int("an element type")?;
        let n = b.count("the number of elements in the block", 16)?;
        // Binary records have no line ends: the node count must come from the type.
        let Some((_, _, n_nodes)) = u32::try_from(gmsh_type).ok().and_then(type_info) else {
            b.pos = at;
            return Err(b.err(format!("unknown element type {gmsh_type}")));
        };
        let physicals = entities.get(&(dim, entity)).cloned().unwrap_or_default();
        for _ in 0..n {
            let line = b.line();
            let tag = b.size("an element tag")?;
            let mut nodes = Vec::with_capacity(n_nodes);
            for _ in 0..n_nodes {
                nodes.push(b.size("a node tag")?);
            }
            out.push(ElemRec {
                tag,
                gmsh_type: gmsh_type as u32,
                dim: Some(dim),
                physicals: physicals.clone(),
                nodes,
                line,
            });
        }
    }
    if out.len() != n_elements {
        return Err(
            b.err(format!("header declares {n_elements} elements, the blocks hold {}", out.len()))
        );
    }
    Ok(out)
}
