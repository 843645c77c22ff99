//! Reading back the `.vtu` files this crate writes (for `cosdem plot`): a small reader of
//! exactly the layout [`super::vtk::VtuPiece::to_xml_encoded`] produces (one `<DataArray>`
//! element per array, ASCII, inline base64 with a `UInt64` byte-count header, or inline
//! zlib-compressed base64 under `compressor="vtkZLibDataCompressor"`), not a general VTK
//! reader.

use super::vtk::{Cell, CellType, DataArray, VtuPiece};
use super::{Result, invalid, io_err, unescape};
use std::path::Path;

/// Reads a `.vtu` written by [`super::write_vtu`] or [`super::write_vtu_encoded`].
pub fn read_vtu(path: &Path) -> Result<VtuPiece> {
    let text = std::fs::read_to_string(path).map_err(io_err(path, "read"))?;
    parse_vtu(&text, path)
}

/// Where a `<DataArray>` sits.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Section {
    None,
    Field,
    PointData,
    CellData,
    Points,
    Cells,
}

/// Parses the text of a `.vtu`; `path` only names the file in errors.
pub fn parse_vtu(text: &str, path: &Path) -> Result<VtuPiece> {
    let mut piece = VtuPiece::default();
    let mut section = Section::None;
    let (mut connectivity, mut offsets, mut types) = (None, None, None);
    let mut rest = text;
    let mut compressed = false;
    while let Some(open) = rest.find('<') {
        rest = &rest[open..];
        let close = rest.find('>').ok_or_else(|| invalid(path, "unterminated tag".into()))?;
        let tag = &rest[1..close];
        rest = &rest[close + 1..];
        let name = tag.split_whitespace().next().unwrap_or("");
        if name == "VTKFile" {
            compressed = match attribute(tag, "compressor") {
                None => false,
                Some(c) if c == super::vtk_zlib::COMPRESSOR => true,
                Some(c) => return Err(invalid(path, format!("unsupported compressor {c:?}"))),
            };
        }
        section = match name {
            "FieldData" => Section::Field,
            "PointData" => Section::PointData,
            "CellData" => Section::CellData,
            "Points" => Section::Points,
            "Cells" => Section::Cells,
            "/FieldData" | "/PointData" | "/CellData" | "/Points" | "/Cells" => Section::None,
            _ => section,
        };
        if name != "DataArray" {
            continue;
        }
        let end = rest
            .find("</DataArray>")
            .ok_or_else(|| invalid(path, format!("<{tag}> has no </DataArray>")))?;
        let body = &rest[..end];
        rest = &rest[end + "</DataArray>".len()..];
        let array_name = attribute(tag, "Name").unwrap_or_default();
        let kind = attribute(tag, "type").unwrap_or_default();
        let format = attribute(tag, "format").unwrap_or_else(|| "ascii".into());
        let values = decode(body, &kind, &format, compressed)
            .map_err(|m| invalid(path, format!("array {array_name:?}: {m}")))?;
        let components: usize = match attribute(tag, "NumberOfComponents") {
            Some(c) => c.parse().map_err(|_| {
                invalid(path, format!("array {array_name:?}: NumberOfComponents = {c:?}"))
            })?,
            None => 1,
        };
        match section {
            Section::Field if array_name == "TimeValue" => piece.time = values.first().copied(),
            Section::PointData | Section::CellData => {
                let mut a = DataArray::new(array_name.clone(), components, values);
                a.int32 = kind == "Int32";
                let names: Vec<String> = (0..components)
                    .map_while(|i| attribute(tag, &format!("ComponentName{i}")))
                    .collect();
                if names.len() == components {
                    a.component_names = names;
                }
                if section == Section::PointData {
                    piece.point_data.push(a);
                } else {
                    piece.cell_data.push(a);
                }
            }
            Section::Points => {
                if components != 3 || values.len() % 3 != 0 {
                    return Err(invalid(path, format!("Points: {} values", values.len())));
                }
                piece.points = values.chunks(3).map(|p| [p[0], p[1], p[2]]).collect();
            }
            Section::Cells => match array_name.as_str() {
                "connectivity" => connectivity = Some(values),
                "offsets" => offsets = Some(values),
                "types" => types = Some(values),
                _ => {}
            },
            _ => {}
        }
    }
    let (Some(conn), Some(offs), Some(types)) = (connectivity, offsets, types) else {
        return Err(invalid(path, "missing connectivity, offsets or types".into()));
    };
    if offs.len() != types.len() {
        return Err(invalid(path, format!("{} offsets for {} types", offs.len(), types.len())));
    }
    let mut start = 0usize;
    for (i, (&o, &t)) in offs.iter().zip(&types).enumerate() {
        let end = o as usize;
        let cell_type = cell_type(t as u8)
            .ok_or_else(|| invalid(path, format!("cell {i} has the unknown VTK type {t}")))?;
        if end < start || end > conn.len() {
            return Err(invalid(path, format!("cell {i} has the offset {o}")));
        }
        let nodes = conn[start..end].iter().map(|&n| n as usize).collect();
        piece.cells.push(Cell { cell_type, nodes });
        start = end;
    }
    Ok(piece)
}

impl VtuPiece {
    /// The point array `name`, if the piece has one.
    pub fn point_array(&self, name: &str) -> Option<&DataArray> {
        self.point_data.iter().find(|a| a.name == name)
    }

    /// The cell array `name`, if the piece has one.
    pub fn cell_array(&self, name: &str) -> Option<&DataArray> {
        self.cell_data.iter().find(|a| a.name == name)
    }
}

fn cell_type(id: u8) -> Option<CellType> {
    [
        CellType::Vertex,
        CellType::Line,
        CellType::Triangle,
        CellType::Quad,
        CellType::QuadraticEdge,
        CellType::QuadraticTriangle,
        CellType::QuadraticQuad,
        CellType::BiquadraticQuad,
    ]
    .into_iter()
    .find(|c| c.vtk_id() == id)
}

/// The value of `name="..."` in a tag (XML entities of the writer undone).
pub(crate) fn attribute(tag: &str, name: &str) -> Option<String> {
    let key = format!(" {name}=\"");
    let start = tag.find(&key)? + key.len();
    let len = tag[start..].find('"')?;
    Some(unescape(&tag[start..start + len]))
}

/// The numbers of one array as `f64` (integers are exact up to 2^53).
fn decode(
    body: &str,
    kind: &str,
    format: &str,
    compressed: bool,
) -> std::result::Result<Vec<f64>, String> {
    match format {
        "ascii" => body
            .split_whitespace()
            .map(|t| t.parse::<f64>().map_err(|_| format!("{t:?} is not a number")))
            .collect(),
        "binary" => {
            let raw;
            let data = if compressed {
                raw = super::vtk_zlib::decode_compressed(body)?;
                &raw[..]
            } else {
                raw = base64(body.trim())?;
                if raw.len() < 8 {
                    return Err("binary array shorter than its header".into());
                }
                let n = u64::from_le_bytes(raw[..8].try_into().expect("8 bytes")) as usize;
                let data = &raw[8..];
                if n > data.len() {
                    return Err(format!("header says {n} bytes, {} present", data.len()));
                }
                &data[..n]
            };
            let take8 = |c: &[u8]| -> [u8; 8] { c.try_into().expect("8 bytes") };
            Ok(match kind {
                "Float64" => data.chunks_exact(8).map(|c| f64::from_le_bytes(take8(c))).collect(),
                "Int64" => {
                    data.chunks_exact(8).map(|c| i64::from_le_bytes(take8(c)) as f64).collect()
                }
                "UInt8" => data.iter().map(|&b| f64::from(b)).collect(),
                "Int32" => data
                    .chunks_exact(4)
                    .map(|c| f64::from(i32::from_le_bytes(c.try_into().expect("4 bytes"))))
                    .collect(),
                other => return Err(format!("unsupported binary type {other:?}")),
            })
        }
        other => Err(format!("unsupported format {other:?}")),
    }
}

/// Standard base64 (RFC 4648, padded) decoded; whitespace ignored.
pub(super) fn base64(text: &str) -> std::result::Result<Vec<u8>, String> {
    let value = |c: u8| -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            b'/' => 63,
            _ => return None,
        } as u32)
    };
    let clean: Vec<u8> = text.bytes().filter(|b| !b.is_ascii_whitespace()).collect();
    if !clean.len().is_multiple_of(4) {
        return Err("base64 text length is not a multiple of 4".into());
    }
    let mut out = Vec::with_capacity(clean.len() / 4 * 3);
    for chunk in clean.chunks(4) {
        let pad = chunk.iter().rev().take_while(|&&c| c == b'=').count();
        let mut n = 0u32;
        for &c in &chunk[..4 - pad] {
            n = (n << 6)
                | value(c).ok_or_else(|| format!("bad base64 character {:?}", c as char))?;
        }
        n <<= 6 * pad as u32;
        let bytes = [(n >> 16) as u8, (n >> 8) as u8, n as u8];
        out.extend_from_slice(&bytes[..3 - pad]);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::vtk::Encoding;

    fn sample() -> VtuPiece {
        let mut p = VtuPiece::point_cloud_2d(&[[0.0, 0.0], [1.0, 0.5], [0.25, -2.0]]);
        p.push_cell(CellType::Line, vec![0, 2]);
        p.add_point_data(DataArray::scalars("radius", vec![0.1, 1.0 / 3.0, 2.5e-7]));
        p.add_point_data(
            DataArray::vectors_2d("fluct <&>", &[[1.0, 2.0], [3.0, -4.0], [5e-9, 6.0]])
                .with_component_names(&["x", "y", "z"]),
        );
        p.add_cell_data(DataArray::scalars("normal_force", vec![0.0, 0.0, 0.0, 12.5]));
        p.add_point_data(DataArray::ids("element_id", &[0, 7, u32::MAX >> 1]));
        p.time = Some(0.0125);
        p
    }

    /// What is written is read back bit for bit, in all three encodings (the writer prints the
    /// shortest round-trip decimal, so ASCII is exact too).
    #[test]
    fn round_trip_both_encodings() {
        let path = Path::new("sample.vtu");
        for enc in [Encoding::Ascii, Encoding::Base64, Encoding::Zlib] {
            let p = sample();
            let xml = p.to_xml_encoded(path, enc).unwrap();
            let back = parse_vtu(&xml, path).unwrap();
            assert_eq!(back, p, "{enc:?}");
        }
    }

    #[test]
    fn broken_files_name_the_problem() {
        let path = Path::new("bad.vtu");
        let xml = sample().to_xml(path).unwrap();
        let cut = &xml[..xml.find("<Cells>").unwrap()];
        let e = parse_vtu(cut, path).unwrap_err().to_string();
        assert!(e.contains("bad.vtu") && e.contains("connectivity"), "{e}");
        let bad = xml.replacen("0.1\n", "zero\n", 1);
        let e = parse_vtu(&bad, path).unwrap_err().to_string();
        assert!(e.contains("radius") && e.contains("zero"), "{e}");
    }
}
