//! VTK XML unstructured grids (`.vtu`, ASCII or base64 binary), readable by ParaView and VTK.
//!
//! One generic [`VtuPiece`] (points, cells of any [`CellType`], named `f64` arrays with any
//! number of components on points and cells) serves every output of the solver; the
//! constructors below build the usual ones:
//! - [`nodal_piece`]: the mesh of 8-/9-node quadrilaterals or 6-node triangles with
//!   `displacement` (3 components, z = 0) and `rotation` (the micro-rotation w);
//! - [`gauss_point_piece`]: a point cloud of the Gauss points (`VTK_VERTEX` cells) with
//!   `strain`, `curvature`, `stress`, `couple_stress` and `equivalent_strain` (Eq. 34);
//! - [`particle_piece`]: a DEM snapshot, one vertex per disc with `radius`, `rotation` and
//!   `fluctuation`, then one `VTK_LINE` per contact with the cell array `normal_force`.

use std::fmt::Write as _;
use std::path::Path;

use super::{OutputError, Result, invalid, push_f64, write_atomic};
use cosdem_fem::gmsh::SurfaceKind;

/// The VTK cell types the solver writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CellType {
    /// `VTK_VERTEX` (1): one point (Gauss points, particles).
    Vertex,
    /// `VTK_LINE` (3): two points (force chains).
    Line,
    /// `VTK_TRIANGLE` (5).
    Triangle,
    /// `VTK_QUAD` (9): 4-node quadrilateral.
    Quad,
    /// `VTK_QUADRATIC_EDGE` (21): 3-node line, ends then middle.
    QuadraticEdge,
    /// `VTK_QUADRATIC_TRIANGLE` (22): 6-node triangle, corners then the mid-sides of 0-1,
    /// 1-2 and 2-0 (Gmsh's order for its type 9).
    QuadraticTriangle,
    /// `VTK_QUADRATIC_QUAD` (23): 8-node quadrilateral, corners then mid-edge nodes.
    QuadraticQuad,
    /// `VTK_BIQUADRATIC_QUAD` (28): 9-node quadrilateral, corners, mid-edge nodes, centre.
    BiquadraticQuad,
}

impl CellType {
    /// The VTK type number written to the file.
    pub const fn vtk_id(self) -> u8 {
        match self {
            CellType::Vertex => 1,
            CellType::Line => 3,
            CellType::Triangle => 5,
            CellType::Quad => 9,
            CellType::QuadraticEdge => 21,
            CellType::QuadraticTriangle => 22,
            CellType::QuadraticQuad => 23,
            CellType::BiquadraticQuad => 28,
        }
    }

    /// Number of nodes of one cell.
    pub const fn node_count(self) -> usize {
        match self {
            CellType::Vertex => 1,
            CellType::Line => 2,
            CellType::Triangle => 3,
            CellType::Quad => 4,
            CellType::QuadraticEdge => 3,
            CellType::QuadraticTriangle => 6,
            CellType::QuadraticQuad => 8,
            CellType::BiquadraticQuad => 9,
        }
    }

    /// The quadrilateral with `n` nodes (4, 8 or 9), if any.
    pub const fn quad_with_nodes(n: usize) -> Option<CellType> {
        match n {
            4 => Some(CellType::Quad),
            8 => Some(CellType::QuadraticQuad),
            9 => Some(CellType::BiquadraticQuad),
            _ => None,
        }
    }

    /// The 2D element cell with `n` nodes in Gmsh order (3 or 6: a triangle; 4, 8 or 9: a
    /// quadrilateral), if any. No two of the solver's element families share a node count.
    pub const fn element_with_nodes(n: usize) -> Option<CellType> {
        match n {
            3 => Some(CellType::Triangle),
            6 => Some(CellType::QuadraticTriangle),
            n => Self::quad_with_nodes(n),
        }
    }
}

impl From<SurfaceKind> for CellType {
    fn from(kind: SurfaceKind) -> Self {
        match kind {
            SurfaceKind::Q8 => CellType::QuadraticQuad,
            SurfaceKind::Q9 => CellType::BiquadraticQuad,
            SurfaceKind::T6 => CellType::QuadraticTriangle,
        }
    }
}

/// A named array of `f64` tuples, one tuple per point or per cell.
#[derive(Clone, Debug, PartialEq)]
pub struct DataArray {
    /// Array name as shown in ParaView (any text; escaped on output).
    pub name: String,
    /// Components per tuple (1 for a scalar, 3 for a vector ParaView can glyph).
    pub components: usize,
    /// The values, tuple after tuple: `components * tuples` of them.
    pub values: Vec<f64>,
    /// Optional names of the components (`ComponentName0..`): empty, or one per component.
    pub component_names: Vec<String>,
    /// Stored as `Int32` instead of `Float64` (ids: every value an integer in `i32` range).
    pub int32: bool,
}

impl DataArray {
    /// An array of `components`-tuples stored flat.
    pub fn new(name: impl Into<String>, components: usize, values: Vec<f64>) -> Self {
        DataArray {
            name: name.into(),
            components,
            values,
            component_names: Vec::new(),
            int32: false,
        }
    }

    /// A scalar `Int32` array of ids (element numbers, point numbers).
    pub fn ids(name: impl Into<String>, ids: &[u32]) -> Self {
        let mut a = Self::scalars(name, ids.iter().map(|&i| f64::from(i)).collect());
        a.int32 = true;
        a
    }

    /// A scalar array.
    pub fn scalars(name: impl Into<String>, values: Vec<f64>) -> Self {
        Self::new(name, 1, values)
    }

    /// An array of fixed-size tuples.
    pub fn from_tuples<const N: usize>(name: impl Into<String>, tuples: &[[f64; N]]) -> Self {
        Self::new(name, N, tuples.iter().flatten().copied().collect())
    }

    /// A 3-component vector array from 2D vectors, with z = 0 (what ParaView glyphs and warps).
    pub fn vectors_2d(name: impl Into<String>, vectors: &[[f64; 2]]) -> Self {
        Self::new(name, 3, vectors.iter().flat_map(|v| [v[0], v[1], 0.0]).collect())
    }

    /// Names the components (`ComponentName0`, ... in the file).
    pub fn with_component_names(mut self, names: &[&str]) -> Self {
        self.component_names = names.iter().map(|s| s.to_string()).collect();
        self
    }
}

/// One cell: its type and its node indices (0-based, into [`VtuPiece::points`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Cell {
    /// VTK cell type.
    pub cell_type: CellType,
    /// Node indices, in VTK order for the type.
    pub nodes: Vec<usize>,
}

/// Everything one `.vtu` file holds: an unstructured grid with point and cell arrays.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VtuPiece {
    /// Point coordinates (z = 0 for the 2D solver).
    pub points: Vec<[f64; 3]>,
    /// The cells.
    pub cells: Vec<Cell>,
    /// Arrays with one tuple per point.
    pub point_data: Vec<DataArray>,
    /// Arrays with one tuple per cell.
    pub cell_data: Vec<DataArray>,
    /// Optional time written as the field array `TimeValue` (ParaView reads it for file
    /// series opened without a `.pvd`).
    pub time: Option<f64>,
}

impl VtuPiece {
    /// A piece with these points and no cells or arrays.
    pub fn new(points: Vec<[f64; 3]>) -> Self {
        VtuPiece { points, ..Default::default() }
    }

    /// A piece with 2D points lifted to z = 0.
    pub fn from_points_2d(points: &[[f64; 2]]) -> Self {
        Self::new(points.iter().map(|p| [p[0], p[1], 0.0]).collect())
    }

    /// A point cloud: 2D points (z = 0) with one `VTK_VERTEX` cell each.
    pub fn point_cloud_2d(points: &[[f64; 2]]) -> Self {
        let mut piece = Self::from_points_2d(points);
        piece.cells = (0..points.len())
            .map(|i| Cell { cell_type: CellType::Vertex, nodes: vec![i] })
            .collect();
        piece
    }

    /// Appends one cell.
    pub fn push_cell(&mut self, cell_type: CellType, nodes: Vec<usize>) {
        self.cells.push(Cell { cell_type, nodes });
    }

    /// Appends a point array.
    pub fn add_point_data(&mut self, array: DataArray) {
        self.point_data.push(array);
    }

    /// Appends a cell array.
    pub fn add_cell_data(&mut self, array: DataArray) {
        self.cell_data.push(array);
    }

    /// Renders the piece as ASCII VTK XML text; `path` only names the file in errors.
    pub fn to_xml(&self, path: &Path) -> Result<String> {
        self.to_xml_encoded(path, Encoding::Ascii)
    }

    /// Renders the piece as VTK XML text with the arrays in `encoding`; `path` only names the
    /// file in errors.
    pub fn to_xml_encoded(&self, path: &Path, encoding: Encoding) -> Result<String> {
        self.validate(path)?;
        let per_value = match encoding {
            Encoding::Ascii => 24,
            Encoding::Base64 | Encoding::Zlib => 11,
        };
        let values: usize = self.points.len() * 3
            + self.cells.iter().map(|c| c.nodes.len() + 2).sum::<usize>()
            + self.point_data.iter().chain(&self.cell_data).map(|a| a.values.len()).sum::<usize>();
        let mut s = String::with_capacity(per_value * values + 1024);
        s.push_str("<?xml version=\"1.0\"?>\n");
        s.push_str(
            "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" \
             header_type=\"UInt64\"",
        );
        if encoding == Encoding::Zlib {
            let _ = write!(s, " compressor=\"{}\"", super::vtk_zlib::COMPRESSOR);
        }
        s.push_str(">\n  <UnstructuredGrid>\n");
        if let Some(t) = self.time {
            s.push_str("    <FieldData>\n");
            let attrs = "type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\"";
            push_array(&mut s, 6, attrs, Values::F64(&[t], 1), encoding);
            s.push_str("    </FieldData>\n");
        }
        let _ = writeln!(
            s,
            "    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
            self.points.len(),
            self.cells.len()
        );
        for (tag, arrays) in [("PointData", &self.point_data), ("CellData", &self.cell_data)] {
            let _ = writeln!(s, "      <{tag}>");
            for a in arrays {
                let mut attrs = format!(
                    "type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\"",
                    if a.int32 { "Int32" } else { "Float64" },
                    escape(&a.name),
                    a.components
                );
                for (i, c) in a.component_names.iter().enumerate() {
                    let _ = write!(attrs, " ComponentName{i}=\"{}\"", escape(c));
                }
                let ints: Vec<i32>;
                let values = if a.int32 {
                    ints = a.values.iter().map(|&v| v as i32).collect();
                    Values::I32(&ints)
                } else {
                    Values::F64(&a.values, a.components)
                };
                push_array(&mut s, 8, &attrs, values, encoding);
            }
            let _ = writeln!(s, "      </{tag}>");
        }
        s.push_str("      <Points>\n");
        let points = self.points.as_flattened();
        let attrs = "type=\"Float64\" NumberOfComponents=\"3\"";
        push_array(&mut s, 8, attrs, Values::F64(points, 3), encoding);
        s.push_str("      </Points>\n      <Cells>\n");
        let cells = Values::Cells(&self.cells);
        push_array(&mut s, 8, "type=\"Int64\" Name=\"connectivity\"", cells, encoding);
        let mut offset = 0;
        let offsets: Vec<i64> = self
            .cells
            .iter()
            .map(|c| {
                offset += c.nodes.len() as i64;
                offset
            })
            .collect();
        let offsets = Values::I64(&offsets);
        push_array(&mut s, 8, "type=\"Int64\" Name=\"offsets\"", offsets, encoding);
        let types: Vec<u8> = self.cells.iter().map(|c| c.cell_type.vtk_id()).collect();
        push_array(&mut s, 8, "type=\"UInt8\" Name=\"types\"", Values::U8(&types), encoding);
        s.push_str("      </Cells>\n    </Piece>\n");
        s.push_str("  </UnstructuredGrid>\n</VTKFile>\n");
        Ok(s)
    }

    fn validate(&self, path: &Path) -> Result<()> {
        let non_finite = |array: &str, values: &mut dyn Iterator<Item = f64>| -> Result<()> {
            for (index, value) in values.enumerate() {
                if !value.is_finite() {
                    return Err(OutputError::NonFinite {
                        path: path.to_path_buf(),
                        array: array.to_string(),
                        index,
                        value,
                    });
                }
            }
            Ok(())
        };
        non_finite("Points", &mut self.points.iter().flatten().copied())?;
        if let Some(t) = self.time {
            non_finite("TimeValue", &mut std::iter::once(t))?;
        }
        let n_points = self.points.len();
        for (i, c) in self.cells.iter().enumerate() {
            if c.nodes.len() != c.cell_type.node_count() {
                return Err(invalid(
                    path,
                    format!(
                        "cell {i} of type {:?} has {} nodes, expected {}",
                        c.cell_type,
                        c.nodes.len(),
                        c.cell_type.node_count()
                    ),
                ));
            }
            if let Some(&n) = c.nodes.iter().find(|&&n| n >= n_points) {
                return Err(invalid(
                    path,
                    format!("cell {i} refers to point {n}, but the piece has {n_points} points"),
                ));
            }
        }
        for (kind, arrays, tuples) in
            [("point", &self.point_data, n_points), ("cell", &self.cell_data, self.cells.len())]
        {
            for (k, a) in arrays.iter().enumerate() {
                if a.name.trim().is_empty() {
                    return Err(invalid(path, format!("{kind} array {k} has an empty name")));
                }
                if arrays[..k].iter().any(|b| b.name == a.name) {
                    return Err(invalid(path, format!("two {kind} arrays are named {:?}", a.name)));
                }
                if a.components == 0 {
                    return Err(invalid(
                        path,
                        format!("{kind} array {:?} has 0 components", a.name),
                    ));
                }
                if a.values.len() != a.components * tuples {
                    return Err(invalid(
                        path,
                        format!(
                            "{kind} array {:?} has {} values, expected {} ({} components x {tuples} \
                             {kind}s)",
                            a.name,
                            a.values.len(),
                            a.components * tuples,
                            a.components
                        ),
                    ));
                }
                if !a.component_names.is_empty() && a.component_names.len() != a.components {
                    return Err(invalid(
                        path,
                        format!(
                            "{kind} array {:?} has {} component names for {} components",
                            a.name,
                            a.component_names.len(),
                            a.components
                        ),
                    ));
                }
                non_finite(&a.name, &mut a.values.iter().copied())?;
                let not_i32 =
                    |v: f64| v.fract() != 0.0 || v < f64::from(i32::MIN) || v > f64::from(i32::MAX);
                if let Some(v) = a.values.iter().find(|&&v| a.int32 && not_i32(v)) {
                    return Err(invalid(path, format!("Int32 array {:?} holds {v}", a.name)));
                }
            }
        }
        Ok(())
    }
}

/// How the arrays of a `.vtu` are stored.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Encoding {
    /// Decimal text (`format="ascii"`), shortest round-trip form: readable, diffable.
    #[default]
    Ascii,
    /// Raw little-endian bytes, base64-encoded inline (`format="binary"`), each array
    /// preceded by its byte count as a `UInt64`: exact and about half the size.
    Base64,
    /// zlib-compressed blocks, base64-encoded inline (`format="binary"` under
    /// `compressor="vtkZLibDataCompressor"`): exact and several times smaller than ASCII
    /// (see [`super::vtk_zlib`]).
    Zlib,
}

/// The contents of one `DataArray`.
enum Values<'a> {
    /// Values with so many per line (ASCII).
    F64(&'a [f64], usize),
    I64(&'a [i64]),
    I32(&'a [i32]),
    U8(&'a [u8]),
    /// Connectivity: one cell per line (ASCII).
    Cells(&'a [Cell]),
}

/// Writes one `<DataArray ...>` element, indented by `indent` spaces.
fn push_array(s: &mut String, indent: usize, attrs: &str, values: Values<'_>, encoding: Encoding) {
    let pad = " ".repeat(indent);
    let format = match encoding {
        Encoding::Ascii => "ascii",
        Encoding::Base64 | Encoding::Zlib => "binary",
    };
    let _ = writeln!(s, "{pad}<DataArray {attrs} format=\"{format}\">");
    match encoding {
        Encoding::Ascii => match values {
            Values::F64(v, per_line) => {
                for tuple in v.chunks(per_line.max(1)) {
                    s.push_str(&pad);
                    s.push_str("  ");
                    for (i, &x) in tuple.iter().enumerate() {
                        if i > 0 {
                            s.push(' ');
                        }
                        push_f64(s, x);
                    }
                    s.push('\n');
                }
            }
            Values::I64(v) => {
                for x in v {
                    let _ = writeln!(s, "{pad}  {x}");
                }
            }
            Values::U8(v) => {
                for x in v {
                    let _ = writeln!(s, "{pad}  {x}");
                }
            }
            Values::I32(v) => {
                for x in v {
                    let _ = writeln!(s, "{pad}  {x}");
                }
            }
            Values::Cells(cells) => {
                for c in cells {
                    s.push_str(&pad);
                    s.push_str("  ");
                    for (i, n) in c.nodes.iter().enumerate() {
                        if i > 0 {
                            s.push(' ');
                        }
                        let _ = write!(s, "{n}");
                    }
                    s.push('\n');
                }
            }
        },
        Encoding::Base64 | Encoding::Zlib => {
            let mut bytes = Vec::new();
            bytes.extend_from_slice(&[0; 8]);
            match values {
                Values::F64(v, _) => {
                    v.iter().for_each(|x| bytes.extend_from_slice(&x.to_le_bytes()))
                }
                Values::I64(v) => v.iter().for_each(|x| bytes.extend_from_slice(&x.to_le_bytes())),
                Values::U8(v) => bytes.extend_from_slice(v),
                Values::I32(v) => v.iter().for_each(|x| bytes.extend_from_slice(&x.to_le_bytes())),
                Values::Cells(cells) => cells.iter().flat_map(|c| &c.nodes).for_each(|&n| {
                    bytes.extend_from_slice(&(n as i64).to_le_bytes());
                }),
            }
            let len = (bytes.len() - 8) as u64;
            bytes[..8].copy_from_slice(&len.to_le_bytes());
            s.push_str(&pad);
            s.push_str("  ");
            if encoding == Encoding::Zlib {
                super::vtk_zlib::push_compressed(s, &bytes[8..]);
            } else {
                push_base64(s, &bytes);
            }
            s.push('\n');
        }
    }
    let _ = writeln!(s, "{pad}</DataArray>");
}

/// Standard base64 (RFC 4648) with padding.
pub(super) fn push_base64(s: &mut String, bytes: &[u8]) {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    s.reserve(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [chunk[0], *chunk.get(1).unwrap_or(&0), *chunk.get(2).unwrap_or(&0)];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                s.push(ALPHABET[((n >> (18 - 6 * k)) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
}

/// Escapes text for an XML attribute value.
pub(crate) fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for ch in text.chars() {
        match ch {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\n' => out.push_str("&#10;"),
            '\r' => out.push_str("&#13;"),
            '\t' => out.push_str("&#9;"),
            c if (c as u32) < 0x20 => out.push('?'),
            c => out.push(c),
        }
    }
    out
}

/// Writes `piece` to `path` (conventionally `*.vtu`) atomically, as ASCII.
pub fn write_vtu(path: &Path, piece: &VtuPiece) -> Result<()> {
    write_vtu_encoded(path, piece, Encoding::Ascii)
}

/// Writes `piece` to `path` atomically with the arrays in `encoding`.
pub fn write_vtu_encoded(path: &Path, piece: &VtuPiece, encoding: Encoding) -> Result<()> {
    let xml = piece.to_xml_encoded(path, encoding)?;
    write_atomic(path, xml.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cell_types_match_vtk_and_gmsh() {
        for kind in [SurfaceKind::Q8, SurfaceKind::Q9, SurfaceKind::T6] {
            assert_eq!(CellType::from(kind).vtk_id(), kind.vtk_cell_type(), "{kind:?}");
            assert_eq!(CellType::from(kind).node_count(), kind.node_count(), "{kind:?}");
            let by_count = CellType::element_with_nodes(kind.node_count());
            assert_eq!(by_count, Some(CellType::from(kind)), "{kind:?}");
        }
        assert_eq!(CellType::Vertex.vtk_id(), 1);
        assert_eq!(CellType::Line.vtk_id(), 3);
        assert_eq!(CellType::QuadraticTriangle.vtk_id(), 22);
        assert_eq!(CellType::QuadraticTriangle.node_count(), 6);
    }

    /// Every element family of the solver has its cell, found by its node count, and the
    /// count is the cell's.
    #[test]
    fn element_cells_by_node_count() {
        for n in [3, 4, 6, 8, 9] {
            assert_eq!(CellType::element_with_nodes(n).map(CellType::node_count), Some(n));
        }
        assert_eq!(CellType::element_with_nodes(6), Some(CellType::QuadraticTriangle));
        assert_eq!(CellType::element_with_nodes(5), None);
        assert_eq!(CellType::quad_with_nodes(6), None);
    }

    #[test]
    fn base64_matches_rfc_4648() {
        let enc = |b: &[u8]| {
            let mut s = String::new();
            push_base64(&mut s, b);
            s
        };
        assert_eq!(enc(b""), "");
        assert_eq!(enc(b"f"), "Zg==");
        assert_eq!(enc(b"fo"), "Zm8=");
        assert_eq!(enc(b"foo"), "Zm9v");
        assert_eq!(enc(b"foob"), "Zm9vYg==");
        assert_eq!(enc(b"fooba"), "Zm9vYmE=");
        assert_eq!(enc(b"foobar"), "Zm9vYmFy");
        assert_eq!(enc(&[0xff, 0xfe, 0x00]), "//4A");
    }

    #[test]
    fn escape_attribute_text() {
        assert_eq!(escape("a<b & \"c\">'d'"), "a&lt;b &amp; &quot;c&quot;&gt;&apos;d&apos;");
    }
}
