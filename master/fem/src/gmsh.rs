//! Gmsh `.msh` reader for meshes of 8- and 9-node quadrilaterals.
//!
//! Reads the ASCII formats 2.2 (`gmsh -format msh22`) and 4.1 (`-format msh41`, Gmsh's
//! default), and binary 4.1 (`-format msh41 -bin`), into a [`RawMesh`]: node coordinates,
//! quadrilateral connectivity and the named physical groups, with no finite-element types.
//!
//! What is kept:
//! - 2D elements of Gmsh type 16 (8-node serendipity, [`QuadKind::Q8`]) and type 10 (9-node
//!   Lagrange, [`QuadKind::Q9`]). Any other 2D or 3D element type is an error naming the type.
//!   Corner order is made counter-clockwise: an element whose corners turn clockwise is
//!   mirrored (corners `0 3 2 1`, mid-edge nodes `7 6 5 4`, centre stays).
//! - 0D and 1D elements (points, 2- and 3-node lines) that belong to a physical group: their
//!   nodes form [`RawMesh::node_groups`], and 3-node lines form [`RawMesh::edge_groups`].
//!   Points and lines without a physical group are ignored.
//!
//! Nodes are renumbered `0..n` in increasing Gmsh tag order; nodes that no kept element uses
//! (e.g. the centre point of a circle arc) are dropped. Elements keep increasing tag order.
//! A physical group without a name in `$PhysicalNames` is named by its number (`"7"`).
//! Format 2.2 repeats an element once per physical group it belongs to (under new tags); each
//! element is read once, and an element in several physical surfaces takes the first one.
//! Every node must lie in the plane z = 0 (to within 1e-12 relative to its distance from the
//! origin).

use std::collections::{BTreeMap, BTreeSet, HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// Why a `.msh` file could not be read. Every variant names the file (`<string>` for
/// [`parse_msh`]) and, where one exists, the 1-based line and the offending value.
#[derive(Debug, thiserror::Error)]
pub enum GmshError {
    /// The file could not be read.
    #[error("{}: cannot read mesh file: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating-system error.
        source: std::io::Error,
    },
    /// A line does not have the expected content.
    #[error("{file}:{line}: {message}")]
    Syntax {
        /// The file.
        file: String,
        /// 1-based line number.
        line: usize,
        /// What was expected and what was found.
        message: String,
    },
    /// The `$MeshFormat` version or file type is not one this reader handles.
    #[error(
        "{file}:{line}: unsupported mesh format {found:?}; supported are ASCII 2.2 and 4.1 \
         (export with `gmsh -format msh22` or `-format msh41`, without `-bin`)"
    )]
    UnsupportedFormat {
        /// The file.
        file: String,
        /// 1-based line number.
        line: usize,
        /// The `$MeshFormat` line.
        found: String,
    },
    /// An element type that the solver cannot use.
    #[error(
        "{file}:{line}: element {element} has unsupported Gmsh type {element_type} ({name}); \
         2D meshes must consist of 8-node (type 16) or 9-node (type 10) quadrilaterals, and \
         boundary groups of 2- or 3-node lines (types 1, 8) or points (type 15)"
    )]
    UnsupportedElement {
        /// The file.
        file: String,
        /// 1-based line number.
        line: usize,
        /// The element's Gmsh tag.
        element: u64,
        /// The Gmsh element type number.
        element_type: u32,
        /// Gmsh's description of that type.
        name: &'static str,
    },
    /// A node lies outside the plane z = 0.
    #[error("{file}:{line}: node {node} has z = {z:e}; only planar meshes in z = 0 are supported")]
    NonPlanar {
        /// The file.
        file: String,
        /// 1-based line number.
        line: usize,
        /// The node's Gmsh tag.
        node: u64,
        /// Its z coordinate.
        z: f64,
    },
    /// An element refers to a node tag that `$Nodes` does not define.
    #[error("{file}:{line}: element {element} refers to node {node}, which $Nodes does not define")]
    UnknownNode {
        /// The file.
        file: String,
        /// 1-based line number.
        line: usize,
        /// The element's Gmsh tag.
        element: u64,
        /// The undefined node tag.
        node: u64,
    },
    /// A quadrilateral whose corners enclose (almost) no area.
    #[error("{file}:{line}: element {element} is degenerate: its corners enclose area {area:e}")]
    DegenerateElement {
        /// The file.
        file: String,
        /// 1-based line number.
        line: usize,
        /// The element's Gmsh tag.
        element: u64,
        /// Signed area of the corner polygon.
        area: f64,
    },
    /// The file as a whole is incomplete (a missing section, no quadrilaterals, ...).
    #[error("{file}: {message}")]
    Structure {
        /// The file.
        file: String,
        /// What is missing.
        message: String,
    },
}

/// Result of the mesh readers.
pub type Result<T> = std::result::Result<T, GmshError>;

/// The two quadratic quadrilaterals the solver supports.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum QuadKind {
    /// 8-node serendipity quadrilateral (Gmsh type 16, VTK type 23).
    Q8,
    /// 9-node Lagrange quadrilateral (Gmsh type 10, VTK type 28).
    Q9,
}

impl QuadKind {
    /// Number of nodes of one element.
    pub const fn node_count(self) -> usize {
        match self {
            QuadKind::Q8 => 8,
            QuadKind::Q9 => 9,
        }
    }

    /// Gmsh element type number.
    pub const fn gmsh_type(self) -> u32 {
        match self {
            QuadKind::Q8 => 16,
            QuadKind::Q9 => 10,
        }
    }

    /// VTK cell type number (`VTK_QUADRATIC_QUAD` = 23, `VTK_BIQUADRATIC_QUAD` = 28); VTK's
    /// node order for these equals Gmsh's.
    pub const fn vtk_cell_type(self) -> u8 {
        match self {
            QuadKind::Q8 => 23,
            QuadKind::Q9 => 28,
        }
    }

    fn from_gmsh_type(t: u32) -> Option<QuadKind> {
        match t {
            16 => Some(QuadKind::Q8),
            10 => Some(QuadKind::Q9),
            _ => None,
        }
    }
}

/// One quadrilateral as read from the file.
#[derive(Clone, Debug, PartialEq)]
pub struct RawElement {
    /// 8- or 9-node.
    pub kind: QuadKind,
    /// 0-based node indices into [`RawMesh::nodes`], in Gmsh order: corners 0-3
    /// counter-clockwise, mid-edge nodes 4 (0-1), 5 (1-2), 6 (2-3), 7 (3-0), centre 8 (Q9).
    pub nodes: Vec<usize>,
    /// Name of the physical surface the element belongs to, if any.
    pub physical: Option<String>,
}

/// A mesh as read from a `.msh` file, before any finite-element structure is built.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RawMesh {
    /// Node coordinates (x, y), indexed 0-based.
    pub nodes: Vec<[f64; 2]>,
    /// The quadrilaterals, in increasing Gmsh element tag order.
    pub elements: Vec<RawElement>,
    /// `$PhysicalNames`: (dimension, physical tag) -> name.
    pub physical_names: BTreeMap<(u32, i32), String>,
    /// Physical name of a 0D or 1D group -> its sorted, unique node indices.
    pub node_groups: BTreeMap<String, Vec<usize>>,
    /// Physical name of a 1D group -> its 3-node line elements, each `[end, end, mid]` as in
    /// Gmsh (2-node lines contribute to [`RawMesh::node_groups`] only).
    pub edge_groups: BTreeMap<String, Vec<Vec<usize>>>,
}

/// Reads a `.msh` file: ASCII 2.2, ASCII 4.1 or binary 4.1.
pub fn read_msh(path: &Path) -> Result<RawMesh> {
    let bytes =
        std::fs::read(path).map_err(|source| GmshError::Io { path: path.to_path_buf(), source })?;
    parse_bytes_named(&bytes, &path.display().to_string())
}

/// Parses the bytes of a `.msh` file (ASCII 2.2, ASCII 4.1 or binary 4.1); errors name the
/// file `<bytes>`.
pub fn parse_msh_bytes(bytes: &[u8]) -> Result<RawMesh> {
    parse_bytes_named(bytes, "<bytes>")
}

fn parse_bytes_named(bytes: &[u8], file: &str) -> Result<RawMesh> {
    // The second line of `$MeshFormat` tells ASCII (file type 0) from binary (1).
    let mut lines = bytes.split(|&b| b == b'\n');
    if lines.next().map(|l| l.trim_ascii()) == Some(b"$MeshFormat".as_slice())
        && let Some(format) = lines.next()
    {
        let t: Vec<&[u8]> =
            format.split(|b| b.is_ascii_whitespace()).filter(|t| !t.is_empty()).collect();
        if t.len() == 3 && t[1] == b"1" {
            if t[0] == b"4.1" && t[2] == b"8" {
                return binary::parse(bytes, file);
            }
            return Err(GmshError::UnsupportedFormat {
                file: file.to_string(),
                line: 2,
                found: String::from_utf8_lossy(format).trim().to_string(),
            });
        }
    }
    match std::str::from_utf8(bytes) {
        Ok(text) => parse_named(text, file),
        Err(e) => {
            let line = 1 + bytes[..e.valid_up_to()].iter().filter(|&&b| b == b'\n').count();
            Err(GmshError::Syntax {
                file: file.to_string(),
                line,
                message: "the text is not valid UTF-8 (a binary file without a binary \
                          $MeshFormat?)"
                    .to_string(),
            })
        }
    }
}

/// Parses the text of an ASCII `.msh` file (2.2 or 4.1); errors name the file `<string>`.
pub fn parse_msh(text: &str) -> Result<RawMesh> {
    parse_named(text, "<string>")
}

// ---------------------------------------------------------------------------------------------
// Records shared by both format versions.

struct NodeRec {
    tag: u64,
    xy: [f64; 2],
}

struct ElemRec {
    tag: u64,
    gmsh_type: u32,
    /// Dimension of the element (from the type table, or the 4.1 entity block).
    dim: Option<u32>,
    /// Physical tags (empty: none).
    physicals: Vec<i32>,
    nodes: Vec<u64>,
    line: usize,
}

/// Gmsh's element types: (description, dimension, node count).
fn type_info(t: u32) -> Option<(&'static str, u32, usize)> {
    Some(match t {
        1 => ("2-node line", 1, 2),
        2 => ("3-node triangle", 2, 3),
        3 => ("4-node quadrangle", 2, 4),
        4 => ("4-node tetrahedron", 3, 4),
        5 => ("8-node hexahedron", 3, 8),
        6 => ("6-node prism", 3, 6),
        7 => ("5-node pyramid", 3, 5),
        8 => ("3-node line", 1, 3),
        9 => ("6-node triangle", 2, 6),
        10 => ("9-node quadrangle", 2, 9),
        11 => ("10-node tetrahedron", 3, 10),
        12 => ("27-node hexahedron", 3, 27),
        13 => ("18-node prism", 3, 18),
        14 => ("14-node pyramid", 3, 14),
        15 => ("1-node point", 0, 1),
        16 => ("8-node quadrangle", 2, 8),
        17 => ("20-node hexahedron", 3, 20),
        18 => ("15-node prism", 3, 15),
        19 => ("13-node pyramid", 3, 13),
        20 => ("9-node incomplete triangle", 2, 9),
        21 => ("10-node triangle", 2, 10),
        22 => ("12-node incomplete triangle", 2, 12),
        23 => ("15-node triangle", 2, 15),
        24 => ("15-node incomplete triangle", 2, 15),
        25 => ("21-node triangle", 2, 21),
        26 => ("4-node line", 1, 4),
        27 => ("5-node line", 1, 5),
        28 => ("6-node line", 1, 6),
        36 => ("16-node quadrangle", 2, 16),
        37 => ("25-node quadrangle", 2, 25),
        _ => return None,
    })
}

/// Line-by-line reader that knows the file name and line numbers.
struct Cursor<'a> {
    file: &'a str,
    lines: Vec<&'a str>,
    pos: usize,
}

impl<'a> Cursor<'a> {
    fn new(text: &'a str, file: &'a str) -> Self {
        Cursor { file, lines: text.lines().collect(), pos: 0 }
    }

    /// Next non-blank line with its 1-based number.
    fn next(&mut self) -> Option<(usize, &'a str)> {
        while self.pos < self.lines.len() {
            let l = self.lines[self.pos];
            self.pos += 1;
            if !l.trim().is_empty() {
                return Some((self.pos, l));
            }
        }
        None
    }

    fn expect(&mut self, what: &str) -> Result<(usize, &'a str)> {
        match self.next() {
            Some(x) => Ok(x),
            None => {
                Err(self
                    .syntax(self.lines.len(), format!("unexpected end of file: expected {what}")))
            }
        }
    }

    /// A line split into fields, for reading one record.
    fn fields(&mut self, what: &str) -> Result<Fields<'a>> {
        let (line, text) = self.expect(what)?;
        Ok(Fields { file: self.file, line, toks: text.split_whitespace() })
    }

    fn end_section(&mut self, name: &str) -> Result<()> {
        let want = format!("$End{name}");
        let (line, text) = self.expect(&want)?;
        if text.trim() != want {
            return Err(self.syntax(line, format!("expected {want}, found {:?}", text.trim())));
        }
        Ok(())
    }

    fn syntax(&self, line: usize, message: String) -> GmshError {
        GmshError::Syntax { file: self.file.to_string(), line, message }
    }
}

struct Fields<'a> {
    file: &'a str,
    line: usize,
    toks: std::str::SplitWhitespace<'a>,
}

impl Fields<'_> {
    fn next<T: FromStr>(&mut self, what: &str) -> Result<T> {
        match self.toks.next() {
            Some(tok) => {
                tok.parse().map_err(|_| self.syntax(format!("expected {what}, found {tok:?}")))
            }
            None => Err(self.syntax(format!("expected {what}, found end of line"))),
        }
    }

    fn count(&mut self, what: &str) -> Result<usize> {
        self.next::<usize>(what)
    }

    fn rest(&mut self) -> Vec<&str> {
        self.toks.by_ref().collect()
    }

    fn finish(&mut self) -> Result<()> {
        match self.toks.next() {
            None => Ok(()),
            Some(tok) => Err(self.syntax(format!("unexpected extra value {tok:?}"))),
        }
    }

    fn syntax(&self, message: String) -> GmshError {
        GmshError::Syntax { file: self.file.to_string(), line: self.line, message }
    }
}

/// Largest count from the file used to pre-allocate, so a corrupt count cannot exhaust memory.
const CAPACITY_HINT: usize = 1 << 16;

#[derive(Clone, Copy, PartialEq)]
enum Version {
    V2,
    V41,
}

fn parse_named(text: &str, file: &str) -> Result<RawMesh> {
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
                entities = parse_entities(&mut cur)?;
                cur.end_section(name)?;
            }
            "Nodes" => {
                nodes = Some(match version {
                    Some(Version::V41) => parse_nodes_41(&mut cur)?,
                    _ => parse_nodes_2(&mut cur)?,
                });
                cur.end_section(name)?;
            }
            "Elements" => {
                elements = Some(match version {
                    Some(Version::V41) => parse_elements_41(&mut cur, &entities)?,
                    _ => parse_elements_2(&mut cur)?,
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

fn structure(file: &str, message: &str) -> GmshError {
    GmshError::Structure { file: file.to_string(), message: message.to_string() }
}

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
fn physical_name_line(file: &str, line: usize, text: &str) -> Result<((u32, i32), String)> {
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

/// 4.1 `$Entities`: (dimension, entity tag) -> physical tags.
fn parse_entities(cur: &mut Cursor<'_>) -> Result<HashMap<(u32, i32), Vec<i32>>> {
    let mut f = cur.fields("the entity counts")?;
    let counts = [
        f.count("the number of points")?,
        f.count("the number of curves")?,
        f.count("the number of surfaces")?,
        f.count("the number of volumes")?,
    ];
    f.finish()?;
    let mut out = HashMap::new();
    for (dim, &n) in counts.iter().enumerate() {
        for _ in 0..n {
            let mut f = cur.fields("an entity")?;
            let tag: i32 = f.next("an entity tag")?;
            let n_coords = if dim == 0 { 3 } else { 6 };
            for _ in 0..n_coords {
                f.next::<f64>("an entity coordinate")?;
            }
            let n_phys = f.count("the number of physical tags")?;
            let mut phys = Vec::with_capacity(n_phys.min(CAPACITY_HINT));
            for _ in 0..n_phys {
                phys.push(f.next::<i32>("a physical tag")?);
            }
            if dim > 0 {
                let n_bound = f.count("the number of bounding entities")?;
                for _ in 0..n_bound {
                    f.next::<i32>("a bounding entity tag")?;
                }
            }
            f.finish()?;
            out.insert((dim as u32, tag), phys);
        }
    }
    Ok(out)
}

fn check_planar(file: &str, line: usize, tag: u64, x: f64, y: f64, z: f64) -> Result<()> {
    let scale = x.abs().max(y.abs()).max(1.0);
    if z.abs() > 1e-12 * scale || !z.is_finite() {
        return Err(GmshError::NonPlanar { file: file.to_string(), line, node: tag, z });
    }
    if !x.is_finite() || !y.is_finite() {
        return Err(GmshError::Syntax {
            file: file.to_string(),
            line,
            message: format!("node {tag} has a non-finite coordinate ({x}, {y})"),
        });
    }
    Ok(())
}

fn parse_nodes_2(cur: &mut Cursor<'_>) -> Result<Vec<(NodeRec, usize)>> {
    let mut f = cur.fields("the number of nodes")?;
    let n = f.count("the number of nodes")?;
    f.finish()?;
    let mut out = Vec::with_capacity(n.min(CAPACITY_HINT));
    for _ in 0..n {
        let mut f = cur.fields("a node `tag x y z`")?;
        let tag: u64 = f.next("a node tag")?;
        let x: f64 = f.next("a node x coordinate")?;
        let y: f64 = f.next("a node y coordinate")?;
        let z: f64 = f.next("a node z coordinate")?;
        f.finish()?;
        check_planar(cur.file, f.line, tag, x, y, z)?;
        out.push((NodeRec { tag, xy: [x, y] }, f.line));
    }
    Ok(out)
}

fn parse_nodes_41(cur: &mut Cursor<'_>) -> Result<Vec<(NodeRec, usize)>> {
    let mut f = cur.fields("the node block header")?;
    let n_blocks = f.count("the number of node blocks")?;
    let n_nodes = f.count("the number of nodes")?;
    f.next::<u64>("the minimum node tag")?;
    f.next::<u64>("the maximum node tag")?;
    f.finish()?;
    let header_line = f.line;
    let mut out = Vec::with_capacity(n_nodes.min(CAPACITY_HINT));
    for _ in 0..n_blocks {
        let mut f = cur.fields("a node block `dim tag parametric count`")?;
        let _dim: u32 = f.next("an entity dimension")?;
        let _tag: i32 = f.next("an entity tag")?;
        let parametric: u32 = f.next("the parametric flag")?;
        let n = f.count("the number of nodes in the block")?;
        f.finish()?;
        if parametric > 1 {
            return Err(f.syntax(format!("expected parametric flag 0 or 1, found {parametric}")));
        }
        let mut tags = Vec::with_capacity(n.min(CAPACITY_HINT));
        for _ in 0..n {
            let mut f = cur.fields("a node tag")?;
            tags.push(f.next::<u64>("a node tag")?);
            f.finish()?;
        }
        for tag in tags {
            let mut f = cur.fields("node coordinates `x y z`")?;
            let x: f64 = f.next("a node x coordinate")?;
            let y: f64 = f.next("a node y coordinate")?;
            let z: f64 = f.next("a node z coordinate")?;
            // Parametric coordinates (if any) follow; they are not needed.
            check_planar(cur.file, f.line, tag, x, y, z)?;
            out.push((NodeRec { tag, xy: [x, y] }, f.line));
        }
    }
    if out.len() != n_nodes {
        return Err(cur.syntax(
            header_line,
            format!("header declares {n_nodes} nodes, the blocks hold {}", out.len()),
        ));
    }
    Ok(out)
}

fn parse_elements_2(cur: &mut Cursor<'_>) -> Result<Vec<ElemRec>> {
    let mut f = cur.fields("the number of elements")?;
    let n = f.count("the number of elements")?;
    f.finish()?;
    let mut out = Vec::with_capacity(n.min(CAPACITY_HINT));
    for _ in 0..n {
        let mut f = cur.fields("an element `tag type ntags tags... nodes...`")?;
        let tag: u64 = f.next("an element tag")?;
        let gmsh_type: u32 = f.next("an element type")?;
        let n_tags = f.count("the number of element tags")?;
        let mut tags = Vec::with_capacity(n_tags.min(CAPACITY_HINT));
        for _ in 0..n_tags {
            tags.push(f.next::<i32>("an element tag value")?);
        }
        let mut nodes = Vec::new();
        while let Some(tok) = f.toks.next() {
            nodes.push(
                tok.parse::<u64>()
                    .map_err(|_| f.syntax(format!("expected a node tag, found {tok:?}")))?,
            );
        }
        // Tag 0 is the physical group (0 = none), tag 1 the elementary entity.
        let physicals = match tags.first() {
            Some(&p) if p != 0 => vec![p],
            _ => Vec::new(),
        };
        let dim = type_info(gmsh_type).map(|i| i.1);
        out.push(ElemRec { tag, gmsh_type, dim, physicals, nodes, line: f.line });
    }
    Ok(out)
}

fn parse_elements_41(
    cur: &mut Cursor<'_>,
    entities: &HashMap<(u32, i32), Vec<i32>>,
) -> Result<Vec<ElemRec>> {
    let mut f = cur.fields("the element block header")?;
    let n_blocks = f.count("the number of element blocks")?;
    let n_elements = f.count("the number of elements")?;
    f.next::<u64>("the minimum element tag")?;
    f.next::<u64>("the maximum element tag")?;
    f.finish()?;
    let header_line = f.line;
    let mut out = Vec::with_capacity(n_elements.min(CAPACITY_HINT));
    for _ in 0..n_blocks {
        let mut f = cur.fields("an element block `dim tag type count`")?;
        let dim: u32 = f.next("an entity dimension")?;
        let entity: i32 = f.next("an entity tag")?;
        let gmsh_type: u32 = f.next("an element type")?;
        let n = f.count("the number of elements in the block")?;
        f.finish()?;
        if dim > 3 {
            return Err(f.syntax(format!("expected an entity dimension 0-3, found {dim}")));
        }
        let physicals = entities.get(&(dim, entity)).cloned().unwrap_or_default();
        for _ in 0..n {
            let mut f = cur.fields("an element `tag nodes...`")?;
            let tag: u64 = f.next("an element tag")?;
            let mut nodes = Vec::new();
            while let Some(tok) = f.toks.next() {
                nodes.push(
                    tok.parse::<u64>()
                        .map_err(|_| f.syntax(format!("expected a node tag, found {tok:?}")))?,
                );
            }
            out.push(ElemRec {
                tag,
                gmsh_type,
                dim: Some(dim),
                physicals: physicals.clone(),
                nodes,
                line: f.line,
            });
        }
    }
    if out.len() != n_elements {
        return Err(cur.syntax(
            header_line,
            format!("header declares {n_elements} elements, the blocks hold {}", out.len()),
        ));
    }
    Ok(out)
}

/// Signed area of the corner polygon of a quadrilateral.
fn corner_area(c: [[f64; 2]; 4]) -> f64 {
    let mut a = 0.0;
    for i in 0..4 {
        let [x0, y0] = c[i];
        let [x1, y1] = c[(i + 1) % 4];
        a += x0 * y1 - x1 * y0;
    }
    0.5 * a
}

/// Node permutation that mirrors a clockwise quadrilateral into a counter-clockwise one.
const MIRROR: [usize; 9] = [0, 3, 2, 1, 7, 6, 5, 4, 8];

fn assemble(
    file: &str,
    physical_names: BTreeMap<(u32, i32), String>,
    nodes: Vec<(NodeRec, usize)>,
    elements: Vec<ElemRec>,
) -> Result<RawMesh> {
    let mut by_tag: HashMap<u64, [f64; 2]> = HashMap::with_capacity(nodes.len());
    for (n, line) in &nodes {
        if by_tag.insert(n.tag, n.xy).is_some() {
            return Err(GmshError::Syntax {
                file: file.to_string(),
                line: *line,
                message: format!("node tag {} is defined twice", n.tag),
            });
        }
    }
    let group_name = |dim: u32, tag: i32| -> String {
        physical_names
            .get(&(dim, tag))
            .or_else(|| physical_names.get(&(dim, tag.abs())))
            .cloned()
            .unwrap_or_else(|| tag.to_string())
    };

    // Format 2.2 repeats an element, under a new tag, once per physical group it belongs to:
    // an element is identified by its type and nodes, and keeps its first tag.
    // Quadrilaterals by element tag.
    let mut quads: BTreeMap<u64, (QuadKind, Vec<u64>, Option<String>, usize)> = BTreeMap::new();
    let mut quad_seen: HashSet<(u32, Vec<u64>)> = HashSet::new();
    // Group name -> element tag -> (gmsh type, node tags), and the elements already in it.
    let mut groups: BTreeMap<String, BTreeMap<u64, (u32, Vec<u64>)>> = BTreeMap::new();
    let mut group_seen: HashSet<(String, u32, Vec<u64>)> = HashSet::new();

    for e in elements {
        let info = type_info(e.gmsh_type);
        let unsupported = || GmshError::UnsupportedElement {
            file: file.to_string(),
            line: e.line,
            element: e.tag,
            element_type: e.gmsh_type,
            name: info.map_or("unknown type", |i| i.0),
        };
        if let Some((name, _, count)) = info
            && e.nodes.len() != count
        {
            return Err(GmshError::Syntax {
                file: file.to_string(),
                line: e.line,
                message: format!(
                    "element {} of type {} ({name}) has {} nodes, expected {count}",
                    e.tag,
                    e.gmsh_type,
                    e.nodes.len()
                ),
            });
        }
        for &n in &e.nodes {
            if !by_tag.contains_key(&n) {
                return Err(GmshError::UnknownNode {
                    file: file.to_string(),
                    line: e.line,
                    element: e.tag,
                    node: n,
                });
            }
        }
        if let Some(kind) = QuadKind::from_gmsh_type(e.gmsh_type) {
            let physical = e.physicals.first().map(|&p| group_name(2, p));
            if !quad_seen.insert((e.gmsh_type, e.nodes.clone())) {
                continue;
            }
            if quads.contains_key(&e.tag) {
                return Err(GmshError::Syntax {
                    file: file.to_string(),
                    line: e.line,
                    message: format!("element tag {} is used twice", e.tag),
                });
            }
            quads.insert(e.tag, (kind, e.nodes, physical, e.line));
            continue;
        }
        match (e.dim, e.gmsh_type) {
            (Some(0 | 1), 1 | 8 | 15) => {
                let dim = e.dim.unwrap_or(1);
                for &p in &e.physicals {
                    let name = group_name(dim, p);
                    if group_seen.insert((name.clone(), e.gmsh_type, e.nodes.clone())) {
                        groups
                            .entry(name)
                            .or_default()
                            .insert(e.tag, (e.gmsh_type, e.nodes.clone()));
                    }
                }
            }
            (Some(0 | 1), _) if e.physicals.is_empty() => {}
            _ => return Err(unsupported()),
        }
    }
    if quads.is_empty() {
        return Err(structure(
            file,
            "no 8-node (type 16) or 9-node (type 10) quadrilaterals: mesh with `-order 2` \
             and recombine the surfaces",
        ));
    }

    // Renumber the used nodes by increasing tag.
    let mut used: BTreeSet<u64> = BTreeSet::new();
    for (_, nodes, _, _) in quads.values() {
        used.extend(nodes.iter().copied());
    }
    for g in groups.values() {
        for (_, nodes) in g.values() {
            used.extend(nodes.iter().copied());
        }
    }
    let index: HashMap<u64, usize> = used.iter().enumerate().map(|(i, &t)| (t, i)).collect();
    let mesh_nodes: Vec<[f64; 2]> = used.iter().map(|t| by_tag[t]).collect();

    let mut out_elements = Vec::with_capacity(quads.len());
    for (tag, (kind, tags, physical, line)) in quads {
        let mut nodes: Vec<usize> = tags.iter().map(|t| index[t]).collect();
        let corners = [0, 1, 2, 3].map(|i| mesh_nodes[nodes[i]]);
        let area = corner_area(corners);
        let mut size: f64 = 0.0;
        for i in 0..4 {
            let (a, b) = (corners[i], corners[(i + 1) % 4]);
            size = size.max((b[0] - a[0]).hypot(b[1] - a[1]));
        }
        if !area.is_finite() || area.abs() <= 1e-12 * size * size {
            return Err(GmshError::DegenerateElement {
                file: file.to_string(),
                line,
                element: tag,
                area,
            });
        }
        if area < 0.0 {
            nodes = (0..kind.node_count()).map(|i| nodes[MIRROR[i]]).collect();
        }
        out_elements.push(RawElement { kind, nodes, physical });
    }

    let mut node_groups = BTreeMap::new();
    let mut edge_groups = BTreeMap::new();
    for (name, elems) in groups {
        let mut set = BTreeSet::new();
        let mut edges = Vec::new();
        for (gmsh_type, tags) in elems.into_values() {
            let idx: Vec<usize> = tags.iter().map(|t| index[t]).collect();
            set.extend(idx.iter().copied());
            if gmsh_type == 8 {
                edges.push(idx);
            }
        }
        node_groups.insert(name.clone(), set.into_iter().collect());
        if !edges.is_empty() {
            edge_groups.insert(name, edges);
        }
    }

    Ok(RawMesh {
        nodes: mesh_nodes,
        elements: out_elements,
        physical_names,
        node_groups,
        edge_groups,
    })
}

/// Binary format 4.1: the same sections as ASCII, with the numbers stored as raw `int`
/// (4 bytes), `size_t` (8 bytes) and `double` (8 bytes) in the writer's byte order.
mod binary {
    use super::*;

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
                    let Some(k) = rest.windows(want.len()).position(|w| w == want.as_bytes())
                    else {
                        return Err(
                            b.err(format!("unexpected end of file: expected {}", &want[1..]))
                        );
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
            return Err(b.err(format!(
                "header declares {n_elements} elements, the blocks hold {}",
                out.len()
            )));
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One 8-node element with its corners listed clockwise.
    const CLOCKWISE: &str = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n8\n\
        1 0 0 0\n2 0 1 0\n3 1 1 0\n4 1 0 0\n5 0 0.5 0\n6 0.5 1 0\n7 1 0.5 0\n8 0.5 0 0\n\
        $EndNodes\n$Elements\n1\n1 16 2 0 1 1 2 3 4 5 6 7 8\n$EndElements\n";

    #[test]
    fn clockwise_element_is_mirrored() {
        let m = parse_msh(CLOCKWISE).unwrap();
        let e = &m.elements[0];
        assert_eq!(e.kind, QuadKind::Q8);
        assert_eq!(e.physical, None);
        // Corners 1 4 3 2 (tags), mid-edge 8 7 6 5 (tags), 0-based.
        assert_eq!(e.nodes, vec![0, 3, 2, 1, 7, 6, 5, 4]);
        let c = [0, 1, 2, 3].map(|i| m.nodes[e.nodes[i]]);
        assert!(corner_area(c) > 0.0);
        // Each mid-edge node sits between the corners of its edge.
        for k in 0..4 {
            let (a, b, mid) =
                (m.nodes[e.nodes[k]], m.nodes[e.nodes[(k + 1) % 4]], m.nodes[e.nodes[4 + k]]);
            assert_eq!([(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0], mid);
        }
    }

    #[test]
    fn errors_name_line_and_value() {
        let bad = CLOCKWISE.replace("3 1 1 0\n", "3 1 x 0\n");
        let msg = parse_msh(&bad).unwrap_err().to_string();
        assert!(msg.starts_with("<string>:8:"), "{msg}");
        assert!(msg.contains("\"x\""), "{msg}");

        let z = CLOCKWISE.replace("3 1 1 0\n", "3 1 1 0.5\n");
        let err = parse_msh(&z).unwrap_err();
        assert!(matches!(err, GmshError::NonPlanar { line: 8, node: 3, .. }), "{err}");

        let tri = CLOCKWISE.replace("1 16 2 0 1 1 2 3 4 5 6 7 8", "1 2 2 0 1 1 2 3");
        let err = parse_msh(&tri).unwrap_err();
        assert!(
            matches!(err, GmshError::UnsupportedElement { line: 17, element_type: 2, .. }),
            "{err}"
        );
        assert!(err.to_string().contains("3-node triangle"), "{err}");

        let short = CLOCKWISE.replace("1 16 2 0 1 1 2 3 4 5 6 7 8", "1 16 2 0 1 1 2 3 4 5 6 7");
        let msg = parse_msh(&short).unwrap_err().to_string();
        assert!(msg.contains(":17:") && msg.contains("has 7 nodes, expected 8"), "{msg}");

        let unknown =
            CLOCKWISE.replace("1 16 2 0 1 1 2 3 4 5 6 7 8", "1 16 2 0 1 1 2 3 4 5 6 7 99");
        let err = parse_msh(&unknown).unwrap_err();
        assert!(matches!(err, GmshError::UnknownNode { node: 99, line: 17, .. }), "{err}");

        let degenerate =
            CLOCKWISE.replace("3 1 1 0\n", "3 0 0 0\n").replace("2 0 1 0\n", "2 0 0 0\n");
        let err = parse_msh(&degenerate).unwrap_err();
        assert!(matches!(err, GmshError::DegenerateElement { element: 1, .. }), "{err}");

        let binary = CLOCKWISE.replace("2.2 0 8", "2.2 1 8");
        let err = parse_msh(&binary).unwrap_err();
        assert!(matches!(err, GmshError::UnsupportedFormat { line: 2, .. }), "{err}");

        let truncated = &CLOCKWISE[..CLOCKWISE.find("$EndNodes").unwrap()];
        let msg = parse_msh(truncated).unwrap_err().to_string();
        assert!(msg.contains("unexpected end of file"), "{msg}");

        let err = parse_msh("hello\n").unwrap_err().to_string();
        assert!(err.contains("<string>:1:") && err.contains("\"hello\""), "{err}");
    }

    #[test]
    fn lines_without_groups_are_ignored_and_unnamed_groups_use_their_number() {
        let text = CLOCKWISE.replace(
            "$Elements\n1\n",
            "$Elements\n5\n7 8 2 0 3 1 4 8\n8 8 2 9 3 4 3 7\n9 15 2 0 1 1\n10 1 2 9 3 3 2\n",
        );
        let m = parse_msh(&text).unwrap();
        assert_eq!(m.elements.len(), 1);
        assert_eq!(m.node_groups.len(), 1);
        assert_eq!(m.node_groups["9"], vec![1, 2, 3, 6]);
        assert_eq!(m.edge_groups["9"], vec![vec![3, 2, 6]]);
    }
}
