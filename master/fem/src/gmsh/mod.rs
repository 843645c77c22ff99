//! Gmsh `.msh` reader for meshes of 8- and 9-node quadrilaterals and 6-node triangles.
//!
//! Reads the ASCII formats 2.2 (`gmsh -format msh22`) and 4.1 (`-format msh41`, Gmsh's
//! default), and binary 4.1 (`-format msh41 -bin`), into a [`RawMesh`]: node coordinates,
//! element connectivity and the named physical groups, with no finite-element types.
//!
//! What is kept:
//! - 2D elements of Gmsh type 16 (8-node serendipity, [`SurfaceKind::Q8`]), type 10 (9-node
//!   Lagrange, [`SurfaceKind::Q9`]) and type 9 (6-node triangle, [`SurfaceKind::T6`]). Any
//!   other 2D or 3D element type is an error naming the type (a first-order 3-node triangle
//!   or 4-node quadrangle with the hint to mesh with `Mesh.ElementOrder = 2`). The kinds may
//!   be mixed in one mesh (what Gmsh's recombination leaves). Corner order is made
//!   counter-clockwise: an element whose corners turn clockwise is mirrored (quadrilaterals:
//!   corners `0 3 2 1`, mid-edge nodes `7 6 5 4`, centre stays; triangles: corners `0 2 1`,
//!   mid-side nodes `5 4 3`).
//! - 0D and 1D elements (points, 2- and 3-node lines) that belong to a physical group: their
//!   nodes form [`RawMesh::node_groups`], and 3-node lines form [`RawMesh::edge_groups`].
//!   Points and lines without a physical group are ignored.
//!
//! Nodes are renumbered `0..n` in increasing Gmsh tag order; nodes that no kept element uses
//! (e.g. the centre point of a circle arc) are dropped. Elements keep increasing tag order.
//! A physical group without a name in `$PhysicalNames` is named by its number (`"7"`).
//! Format 2.2 repeats an element once per physical group it belongs to (under new tags); each
//! element is read once (the same type and node list is the same element, under its first
//! tag) and keeps every physical surface of its copies, in file order
//! ([`RawElement::physicals`]). Format 4.1 gives an element the physical surfaces of its
//! entity, in the order `$Entities` lists them.
//! Every node must lie in the plane z = 0 (to within 1e-12 relative to its distance from the
//! origin).
//!
//! Layout: `ascii` reads the text formats (and the sections both versions share), `v22` and
//! `v41` their version-specific sections, `binary` binary 4.1; all of them produce the
//! records of `records`, which `build` turns into a [`RawMesh`].
//!
//! [`RawMesh`]: crate::gmsh::RawMesh
//! [`RawElement::physicals`]: crate::gmsh::RawElement::physicals
//! [`RawMesh::node_groups`]: crate::gmsh::RawMesh::node_groups
//! [`RawMesh::edge_groups`]: crate::gmsh::RawMesh::edge_groups
//! [`SurfaceKind::Q8`]: crate::gmsh::SurfaceKind::Q8
//! [`SurfaceKind::Q9`]: crate::gmsh::SurfaceKind::Q9
//! [`SurfaceKind::T6`]: crate::gmsh::SurfaceKind::T6

mod ascii;
mod binary;
mod build;
mod file;
pub use file::read_regular;
mod records;
mod v22;
mod v41;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

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
    /// The path names no regular file (a directory, a device such as `/dev/zero`, a FIFO).
    #[error("{}: cannot read mesh file: it is {kind}, not a regular file", path.display())]
    NotAFile {
        /// The path.
        path: PathBuf,
        /// What it is instead (`a directory`, `a character device`, ...).
        kind: &'static str,
    },
    /// The file is larger than any mesh the solver can take ([`MAX_MESH_FILE_BYTES`]).
    #[error(
        "{}: cannot read mesh file: {} bytes ({:.1} MiB) is more than the {} MiB \
         (MAX_MESH_FILE_BYTES) of a mesh of MAX_ELEMENTS = {} quadrilaterals",
        path.display(),
        size,
        *size as f64 / MIB,
        MAX_MESH_FILE_BYTES >> 20,
        crate::mesh::MAX_ELEMENTS
    )]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// Its size, or the bytes read before the limit was passed.
        size: u64,
        /// The limit (bytes).
        limit: u64,
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
        "{file}:{line}: element {element} has unsupported Gmsh type {element_type} ({name}); {hint}"
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
        /// What to do instead: for a first-order triangle or quadrangle, mesh with
        /// `Mesh.ElementOrder = 2`; otherwise the element types the solver takes.
        hint: &'static str,
    },
    /// An element whose shape the solver cannot use: a mid-side node far off its edge or a
    /// non-positive Jacobian (see [`crate::element::shape_defect`]; triangles).
    #[error("{file}:{line}: element {element} is distorted: {reason}")]
    DistortedElement {
        /// The file.
        file: String,
        /// 1-based line number.
        line: usize,
        /// The element's Gmsh tag.
        element: u64,
        /// What is wrong.
        reason: String,
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
    /// An element whose corners enclose (almost) no area.
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
    /// The file as a whole is incomplete (a missing section, no surface elements, ...).
    #[error("{file}: {message}")]
    Structure {
        /// The file.
        file: String,
        /// What is missing.
        message: String,
    },
}

/// Bytes per MiB, for the messages.
const MIB: f64 = (1u64 << 20) as f64;

/// Largest mesh file read (bytes): what a mesh of [`MAX_ELEMENTS`](crate::mesh::MAX_ELEMENTS)
/// 9-node quadrilaterals, the most the solver takes, needs in ASCII with room to spare: about
/// 4 nodes per element at 128 bytes a line (a tag and three coordinates at full precision),
/// and twice as many element lines as quadrilaterals (the boundary lines and points) at 256
/// bytes (a tag, the type, the tags and up to 9 node tags). About 1 GB; a larger file cannot
/// hold a mesh the solver takes, and [`read_msh`] refuses it before reading.
pub const MAX_MESH_FILE_BYTES: u64 = {
    let elements = crate::mesh::MAX_ELEMENTS as u64;
    4 * elements * 128 + 2 * elements * 256
};

/// Result of the mesh readers.
pub type Result<T> = std::result::Result<T, GmshError>;

/// The quadratic surface elements the solver supports.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum SurfaceKind {
    /// 8-node serendipity quadrilateral (Gmsh type 16, VTK type 23).
    Q8,
    /// 9-node Lagrange quadrilateral (Gmsh type 10, VTK type 28).
    Q9,
    /// 6-node triangle (Gmsh type 9, VTK type 22).
    T6,
}

/// The former name of [`SurfaceKind`], from when only quadrilaterals were read.
pub type QuadKind = SurfaceKind;

impl SurfaceKind {
    /// Number of nodes of one element.
    pub const fn node_count(self) -> usize {
        match self {
            SurfaceKind::Q8 => 8,
            SurfaceKind::Q9 => 9,
            SurfaceKind::T6 => 6,
        }
    }

    /// Number of corner nodes (they come first): 4 or 3.
    pub const fn corner_count(self) -> usize {
        match self {
            SurfaceKind::Q8 | SurfaceKind::Q9 => 4,
            SurfaceKind::T6 => 3,
        }
    }

    /// True for the triangles.
    pub const fn is_triangle(self) -> bool {
        matches!(self, SurfaceKind::T6)
    }

    /// Gmsh element type number.
    pub const fn gmsh_type(self) -> u32 {
        match self {
            SurfaceKind::Q8 => 16,
            SurfaceKind::Q9 => 10,
            SurfaceKind::T6 => 9,
        }
    }

    /// VTK cell type number (`VTK_QUADRATIC_QUAD` = 23, `VTK_BIQUADRATIC_QUAD` = 28,
    /// `VTK_QUADRATIC_TRIANGLE` = 22); VTK's node order for these equals Gmsh's.
    pub const fn vtk_cell_type(self) -> u8 {
        match self {
            SurfaceKind::Q8 => 23,
            SurfaceKind::Q9 => 28,
            SurfaceKind::T6 => 22,
        }
    }

    fn from_gmsh_type(t: u32) -> Option<SurfaceKind> {
        match t {
            16 => Some(SurfaceKind::Q8),
            10 => Some(SurfaceKind::Q9),
            9 => Some(SurfaceKind::T6),
            _ => None,
        }
    }
}

/// One surface element as read from the file.
#[derive(Clone, Debug, PartialEq)]
pub struct RawElement {
    /// 8- or 9-node quadrilateral or 6-node triangle.
    pub kind: SurfaceKind,
    /// 0-based node indices into [`RawMesh::nodes`], in Gmsh order, counter-clockwise.
    /// Quadrilaterals: corners 0-3, mid-edge nodes 4 (0-1), 5 (1-2), 6 (2-3), 7 (3-0), centre
    /// 8 (Q9). Triangles: corners 0-2, mid-side nodes 3 (0-1), 4 (1-2), 5 (2-0).
    pub nodes: Vec<usize>,
    /// Names of every physical surface the element belongs to, in file order, each once
    /// (empty: none). An element may be in several.
    pub physicals: Vec<String>,
}

/// A mesh as read from a `.msh` file, before any finite-element structure is built.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RawMesh {
    /// Node coordinates (x, y), indexed 0-based.
    pub nodes: Vec<[f64; 2]>,
    /// The surface elements, in increasing Gmsh element tag order.
    pub elements: Vec<RawElement>,
    /// `$PhysicalNames`: (dimension, physical tag) -> name.
    pub physical_names: BTreeMap<(u32, i32), String>,
    /// Physical name of a 0D or 1D group -> its sorted, unique node indices.
    pub node_groups: BTreeMap<String, Vec<usize>>,
    /// Physical name of a 1D group -> its 3-node line elements, each `[end, end, mid]` as in
    /// Gmsh (2-node lines contribute to [`RawMesh::node_groups`] only).
    pub edge_groups: BTreeMap<String, Vec<Vec<usize>>>,
}

/// Reads a `.msh` file: ASCII 2.2, ASCII 4.1 or binary 4.1. Only a regular file is read
/// ([`GmshError::NotAFile`] for a directory, a device or a FIFO), and only up to
/// [`MAX_MESH_FILE_BYTES`] ([`GmshError::TooLarge`]).
pub fn read_msh(path: &Path) -> Result<RawMesh> {
    let bytes = file::read_regular(path, MAX_MESH_FILE_BYTES)?;
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
        Ok(text) => ascii::parse_named(text, file),
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
    ascii::parse_named(text, "<string>")
}

/// A [`GmshError::Structure`] for `file`.
fn structure(file: &str, message: &str) -> GmshError {
    GmshError::Structure { file: file.to_string(), message: message.to_string() }
}

#[cfg(test)]
mod tests {
    use super::build::corner_area;
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
        assert!(e.physicals.is_empty());
        // Corners 1 4 3 2 (tags), mid-edge 8 7 6 5 (tags), 0-based.
        assert_eq!(e.nodes, vec![0, 3, 2, 1, 7, 6, 5, 4]);
        let c = [0, 1, 2, 3].map(|i| m.nodes[e.nodes[i]]);
        // Counter-clockwise now: the unit square's area, +1 (exact: sums of 0s and 1s).
        assert_eq!(corner_area(c), 1.0);
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
