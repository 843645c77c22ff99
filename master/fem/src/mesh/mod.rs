//! The macro mesh: nodes, quadratic elements (8- and 9-node quadrilaterals and 6-node
//! triangles, alone or mixed: their edges are all 3-node lines) and named node, edge and
//! element sets.
//!
//! Every mesh, structured or read from a file, goes through [`Mesh::from_description`]: the
//! Gmsh reader only has to fill a [`MeshDescription`].
//!
//! [`Mesh::from_description`]: crate::mesh::Mesh::from_description
//! [`MeshDescription`]: crate::mesh::MeshDescription

mod structured;
pub use structured::MAX_ELEMENTS;

use crate::element::{ElementKind, shape_defect};
use crate::error::{Error, Result};
use std::collections::{BTreeMap, HashMap};

/// A mesh as a reader produces it: coordinates, element node lists in Gmsh order and named
/// physical groups. Indices are 0-based.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshDescription {
    /// Node coordinates `[x, y]` (m).
    pub nodes: Vec<[f64; 2]>,
    /// Element node lists: 8 (Gmsh type 16), 9 (type 10) or 6 (type 9, triangle) nodes in
    /// Gmsh order; the kinds may be mixed.
    pub elements: Vec<Vec<usize>>,
    /// Named node groups (Gmsh physical points or any node list).
    pub node_groups: BTreeMap<String, Vec<usize>>,
    /// Named boundary edge groups, each edge as its 3-node line `[end, end, middle]` (Gmsh
    /// type 8 order); orientation does not matter. Their nodes also form a node set of the
    /// same name.
    pub edge_groups: BTreeMap<String, Vec<[usize; 3]>>,
    /// Named element groups (Gmsh physical surfaces), as 0-based indices into `elements`. An
    /// element may be in several groups, or in none.
    pub element_groups: BTreeMap<String, Vec<usize>>,
}

/// One element edge on a named boundary.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BoundaryEdge {
    /// The element the edge belongs to.
    pub element: usize,
    /// `[start, end, middle]` nodes, counter-clockwise around the element (so the outward
    /// normal is the tangent turned clockwise).
    pub nodes: [usize; 3],
}

/// The macro mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    /// Node coordinates `[x, y]` (m).
    pub nodes: Vec<[f64; 2]>,
    /// Kind of each element.
    pub kinds: Vec<ElementKind>,
    /// Element node lists one after the other (`kinds[e].nodes()` entries for element `e`,
    /// Gmsh order, counter-clockwise); element `e`'s are `offsets[e]..offsets[e + 1]`.
    pub connectivity: Vec<usize>,
    /// Start of each element's nodes in `connectivity`, and its length last.
    pub offsets: Vec<usize>,
    /// Named node sets (sorted, unique node indices).
    pub node_sets: BTreeMap<String, Vec<usize>>,
    /// Named boundary edge sets, for tractions.
    pub edge_sets: BTreeMap<String, Vec<BoundaryEdge>>,
    /// Named element sets (sorted, unique element indices), e.g. the regions of different
    /// materials.
    pub element_sets: BTreeMap<String, Vec<usize>>,
}

fn invalid(field: &'static str, value: impl ToString, reason: impl ToString) -> Error {
    Error::InvalidMesh { field, value: value.to_string(), reason: reason.to_string() }
}

impl Mesh {
    /// Builds and checks a mesh from a raw description.
    ///
    /// Each element's kind follows from its node count (8: Q8, 9: Q9, 6: T6). Elements given
    /// clockwise (signed area of the corner polygon) are renumbered counter-clockwise with
    /// [`ElementKind::flip`]; an element of zero area is an error naming it, and so is an edge
    /// two elements share with different middle nodes (the field would not be continuous). Triangles are also held to [`shape_defect`]
    /// (mid-side nodes within a quarter of the edge length of the edge's midpoint, positive
    /// Jacobian at nodes and integration points), an error naming the element and the node;
    /// quadrilaterals are checked at their Gauss points when the Gauss data are built. Edge
    /// groups are matched to the element that owns them and oriented counter-clockwise
    /// around it. Element groups
    /// become sorted, unique element sets; an index past the last element is an error naming
    /// the group.
    pub fn from_description(desc: MeshDescription) -> Result<Self> {
        let MeshDescription { nodes, elements, node_groups, edge_groups, element_groups } = desc;
        if elements.is_empty() {
            return Err(invalid("elements", 0, "no elements"));
        }
        if elements.len() > MAX_ELEMENTS {
            return Err(invalid(
                "elements",
                elements.len(),
                format!("more than MAX_ELEMENTS = {MAX_ELEMENTS} elements"),
            ));
        }
        for (i, p) in nodes.iter().enumerate() {
            if !(p[0].is_finite() && p[1].is_finite()) {
                return Err(invalid("nodes", i, format!("non-finite coordinates {p:?}")));
            }
        }
        let mut connectivity = Vec::with_capacity(elements.iter().map(Vec::len).sum());
        let mut kinds = Vec::with_capacity(elements.len());
        let mut offsets = Vec::with_capacity(elements.len() + 1);
        for (e, el) in elements.iter().enumerate() {
            let kind = match el.len() {
                8 => ElementKind::Q8,
                9 => ElementKind::Q9,
                6 => ElementKind::T6,
                n => {
                    return Err(invalid(
                        "elements",
                        e,
                        format!("{n} nodes; expected 8 (Q8), 9 (Q9) or 6 (T6)"),
                    ));
                }
            };
            kinds.push(kind);
            offsets.push(connectivity.len());
            if let Some(&bad) = el.iter().find(|&&n| n >= nodes.len()) {
                return Err(invalid("elements", e, format!("node {bad} >= {}", nodes.len())));
            }
            let nc = kind.corners();
            let c: Vec<[f64; 2]> = el[..nc].iter().map(|&n| nodes[n]).collect();
            let area2 = (0..nc)
                .map(|k| c[k][0] * c[(k + 1) % nc][1] - c[(k + 1) % nc][0] * c[k][1])
                .sum::<f64>();
            if area2 == 0.0 || !area2.is_finite() {
                return Err(invalid("elements", e, "zero area"));
            }
            let start = connectivity.len();
            if area2 > 0.0 {
                connectivity.extend_from_slice(el);
            } else {
                connectivity.extend(kind.flip().iter().map(|&k| el[k]));
            }
            if kind.is_triangle() {
                let c: Vec<[f64; 2]> = connectivity[start..].iter().map(|&n| nodes[n]).collect();
                if let Some(defect) = shape_defect(kind, &c) {
                    return Err(invalid("elements", e, defect));
                }
            }
        }
        offsets.push(connectivity.len());
        let element_nodes = |e: usize| &connectivity[offsets[e]..offsets[e + 1]];

        // Edge lookup: sorted end pair -> (element, local edge).
        let mut owner: HashMap<(usize, usize), (usize, usize)> = HashMap::new();
        for e in 0..elements.len() {
            let el = element_nodes(e);
            for (k, ed) in kinds[e].edges().iter().enumerate() {
                let (a, b) = (el[ed[0]], el[ed[1]]);
                if let Some((other, j)) = owner.insert((a.min(b), a.max(b)), (e, k)) {
                    let middle = element_nodes(other)[kinds[other].edges()[j][2]];
                    if middle != el[ed[2]] {
                        return Err(invalid(
                            "elements",
                            e,
                            format!(
                                "its edge {a}-{b} has middle node {}, element {other}'s has {middle}",
                                el[ed[2]]
                            ),
                        ));
                    }
                }
            }
        }
        let mut node_sets: BTreeMap<String, Vec<usize>> = BTreeMap::new();
        for (name, group) in node_groups {
            if let Some(&bad) = group.iter().find(|&&n| n >= nodes.len()) {
                return Err(invalid(
                    "node_groups",
                    &name,
                    format!("node {bad} >= {}", nodes.len()),
                ));
            }
            node_sets.entry(name).or_default().extend(group);
        }
        let mut edge_sets = BTreeMap::new();
        for (name, group) in edge_groups {
            let mut edges = Vec::with_capacity(group.len());
            for line in group {
                let (a, b) = (line[0], line[1]);
                let &(e, k) = owner.get(&(a.min(b), a.max(b))).ok_or_else(|| {
                    invalid("edge_groups", &name, format!("edge {line:?} is no element edge"))
                })?;
                let ed = kinds[e].edges()[k];
                let el = element_nodes(e);
                let oriented = [el[ed[0]], el[ed[1]], el[ed[2]]];
                if oriented[2] != line[2] {
                    return Err(invalid(
                        "edge_groups",
                        &name,
                        format!("edge {line:?}: middle node differs from element {e}'s"),
                    ));
                }
                edges.push(BoundaryEdge { element: e, nodes: oriented });
            }
            node_sets.entry(name.clone()).or_default().extend(edges.iter().flat_map(|e| e.nodes));
            edge_sets.insert(name, edges);
        }
        for set in node_sets.values_mut() {
            set.sort_unstable();
            set.dedup();
        }
        let mut element_sets = BTreeMap::new();
        for (name, mut group) in element_groups {
            if let Some(&bad) = group.iter().find(|&&e| e >= elements.len()) {
                return Err(invalid(
                    "element_groups",
                    &name,
                    format!("element {bad} >= {}", elements.len()),
                ));
            }
            group.sort_unstable();
            group.dedup();
            element_sets.insert(name, group);
        }
        Ok(Self { nodes, kinds, connectivity, offsets, node_sets, edge_sets, element_sets })
    }

    /// Number of elements.
    pub fn n_elements(&self) -> usize {
        self.kinds.len()
    }

    /// Kind of element `e`.
    pub fn element_kind(&self, e: usize) -> ElementKind {
        self.kinds[e]
    }

    /// The one kind of all elements, or `None` for a mesh that mixes kinds.
    pub fn uniform_kind(&self) -> Option<ElementKind> {
        let first = *self.kinds.first()?;
        self.kinds.iter().all(|&k| k == first).then_some(first)
    }

    /// Node lists of all elements, one `Vec` each (Gmsh order): the form output files use.
    pub fn element_lists(&self) -> Vec<Vec<usize>> {
        (0..self.n_elements()).map(|e| self.element_nodes(e).to_vec()).collect()
    }

    /// Number of nodes.
    pub fn n_nodes(&self) -> usize {
        self.nodes.len()
    }

    /// Node indices of element `e`, Gmsh order.
    pub fn element_nodes(&self, e: usize) -> &[usize] {
        &self.connectivity[self.offsets[e]..self.offsets[e + 1]]
    }

    /// Node coordinates of element `e`, Gmsh order.
    pub fn element_coords(&self, e: usize) -> Vec<[f64; 2]> {
        self.element_nodes(e).iter().map(|&n| self.nodes[n]).collect()
    }

    /// A named node set.
    pub fn node_set(&self, name: &str) -> Result<&[usize]> {
        self.node_sets.get(name).map(Vec::as_slice).ok_or_else(|| Error::UnknownSet {
            kind: "node",
            name: name.to_string(),
            known: self.node_sets.keys().cloned().collect::<Vec<_>>().join(", "),
        })
    }

    /// A named boundary edge set.
    pub fn edge_set(&self, name: &str) -> Result<&[BoundaryEdge]> {
        self.edge_sets.get(name).map(Vec::as_slice).ok_or_else(|| Error::UnknownSet {
            kind: "edge",
            name: name.to_string(),
            known: self.edge_sets.keys().cloned().collect::<Vec<_>>().join(", "),
        })
    }

    /// A named element set (sorted element indices).
    pub fn element_set(&self, name: &str) -> Result<&[usize]> {
        self.element_sets.get(name).map(Vec::as_slice).ok_or_else(|| Error::UnknownSet {
            kind: "element",
            name: name.to_string(),
            known: self.element_sets.keys().cloned().collect::<Vec<_>>().join(", "),
        })
    }
}

impl From<crate::gmsh::RawMesh> for MeshDescription {
    /// A Gmsh mesh as read by [`crate::gmsh`]: surface elements, node groups, 3-node boundary
    /// lines (edges of other lengths are not boundary edges of quadratic elements and are
    /// left to the node groups) and element groups from the physical surfaces (an element in
    /// two surfaces is in both groups; whether that is allowed is for the caller to decide).
    fn from(raw: crate::gmsh::RawMesh) -> Self {
        let edge_groups = raw
            .edge_groups
            .into_iter()
            .map(|(name, edges)| {
                let edges = edges
                    .into_iter()
                    .filter_map(|e| <[usize; 3]>::try_from(e.as_slice()).ok())
                    .collect();
                (name, edges)
            })
            .collect();
        let mut element_groups: BTreeMap<String, Vec<usize>> = BTreeMap::new();
        for (e, el) in raw.elements.iter().enumerate() {
            for name in &el.physicals {
                element_groups.entry(name.clone()).or_default().push(e);
            }
        }
        Self {
            nodes: raw.nodes,
            elements: raw.elements.into_iter().map(|e| e.nodes).collect(),
            node_groups: raw.node_groups,
            edge_groups,
            element_groups,
        }
    }
}
