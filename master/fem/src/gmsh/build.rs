//! From the records of any format to a [`RawMesh`]: duplicate elements of format 2.2 merged
//! (their physical surfaces united), nodes checked and renumbered, surface elements
//! oriented counter-clockwise (and triangles checked for their shape), and the points and
//! lines of physical groups turned into node and edge groups.

use super::records::{ElemRec, NodeRec, type_info};
use super::{GmshError, RawElement, RawMesh, Result, SurfaceKind, structure};
use crate::element::{ElementKind, shape_defect};
use std::collections::{BTreeMap, BTreeSet, HashMap, HashSet};

/// Signed area of the corner polygon of an element (3 or 4 corners).
pub(super) fn corner_area(c: impl AsRef<[[f64; 2]]>) -> f64 {
    let c = c.as_ref();
    let n = c.len();
    let mut a = 0.0;
    for i in 0..n {
        let [x0, y0] = c[i];
        let [x1, y1] = c[(i + 1) % n];
        a += x0 * y1 - x1 * y0;
    }
    0.5 * a
}

/// Node permutation that mirrors a clockwise quadrilateral into a counter-clockwise one.
const MIRROR: [usize; 9] = [0, 3, 2, 1, 7, 6, 5, 4, 8];

/// Node permutation that mirrors a clockwise 6-node triangle into a counter-clockwise one.
const MIRROR_TRIANGLE: [usize; 6] = [0, 2, 1, 5, 4, 3];

/// The hint of an unsupported element type: first-order triangles and quadrangles are to be
/// meshed second order.
fn hint(gmsh_type: u32) -> &'static str {
    match gmsh_type {
        2 => {
            "first-order triangles cannot carry the solver's quadratic fields: mesh second \
             order (`Mesh.ElementOrder = 2;` in the .geo file, or `gmsh -order 2`) to get \
             6-node triangles (type 9)"
        }
        3 => {
            "first-order quadrangles cannot carry the solver's quadratic fields: mesh second \
             order (`Mesh.ElementOrder = 2;` in the .geo file, or `gmsh -order 2`; add \
             `Mesh.SecondOrderIncomplete = 1;` for 8-node quadrangles)"
        }
        _ => {
            "2D meshes must consist of 6-node triangles (type 9) or of 8-node (type 16) or \
             9-node (type 10) quadrilaterals, and boundary groups of 2- or 3-node lines \
             (types 1, 8) or points (type 15)"
        }
    }
}

/// Checks the records against each other and builds the [`RawMesh`]: duplicate nodes and
/// element tags, node counts per type, unknown node tags and degenerate quadrilaterals are
/// errors.
pub(super) fn assemble(
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
    // an element is identified by its type and nodes, keeps its first tag, and belongs to the
    // union of the physical surfaces of its copies (in file order).
    // Quadrilaterals by element tag: kind, node tags, physical surfaces, line.
    let mut quads: BTreeMap<u64, (SurfaceKind, Vec<u64>, Vec<String>, usize)> = BTreeMap::new();
    // (type, node tags) -> the first tag of that element.
    let mut quad_seen: HashMap<(u32, Vec<u64>), u64> = HashMap::new();
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
            hint: hint(e.gmsh_type),
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
        if let Some(kind) = SurfaceKind::from_gmsh_type(e.gmsh_type) {
            let mut physicals: Vec<String> = Vec::with_capacity(e.physicals.len());
            for &p in &e.physicals {
                let name = group_name(2, p);
                if !physicals.contains(&name) {
                    physicals.push(name);
                }
            }
            if let Some(first) = quad_seen.get(&(e.gmsh_type, e.nodes.clone())) {
                let known = &mut quads.get_mut(first).expect("a seen element is kept").2;
                for name in physicals {
                    if !known.contains(&name) {
                        known.push(name);
                    }
                }
                continue;
            }
            if quads.contains_key(&e.tag) {
                return Err(GmshError::Syntax {
                    file: file.to_string(),
                    line: e.line,
                    message: format!("element tag {} is used twice", e.tag),
                });
            }
            quad_seen.insert((e.gmsh_type, e.nodes.clone()), e.tag);
            quads.insert(e.tag, (kind, e.nodes, physicals, e.line));
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
            "no 6-node triangles (type 9) or 8-node (type 16) or 9-node (type 10) \
             quadrilaterals: mesh with `-order 2` (and recombine the surfaces for \
             quadrilaterals)",
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
    for (tag, (kind, tags, physicals, line)) in quads {
        let mut nodes: Vec<usize> = tags.iter().map(|t| index[t]).collect();
        let nc = kind.corner_count();
        let corners: Vec<[f64; 2]> = nodes[..nc].iter().map(|&n| mesh_nodes[n]).collect();
        let area = corner_area(&corners);
        let mut size: f64 = 0.0;
        for i in 0..nc {
            let (a, b) = (corners[i], corners[(i + 1) % nc]);
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
            let mirror: &[usize] = if kind.is_triangle() { &MIRROR_TRIANGLE } else { &MIRROR };
            nodes = (0..kind.node_count()).map(|i| nodes[mirror[i]]).collect();
        }
        if kind.is_triangle() {
            let coords: Vec<[f64; 2]> = nodes.iter().map(|&n| mesh_nodes[n]).collect();
            if let Some(reason) = shape_defect(ElementKind::T6, &coords) {
                return Err(GmshError::DistortedElement {
                    file: file.to_string(),
                    line,
                    element: tag,
                    reason,
                });
            }
        }
        out_elements.push(RawElement { kind, nodes, physicals });
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
