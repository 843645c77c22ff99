//! Element sets: Gmsh physical surfaces become named element sets of the mesh, an element in
//! two surfaces belonging to both; structured meshes have none; bad groups are refused.

use cosdem_fem::element::ElementKind;
use cosdem_fem::gmsh::parse_msh;
use cosdem_fem::mesh::{Mesh, MeshDescription};
use std::collections::BTreeMap;

/// Nodes of two 8-node squares side by side, [0, 1] x [0, 1] ("A") and [1, 2] x [0, 1]
/// ("B"), in format 2.2 (`tag x y z`).
const NODES_22: &str = "13\n1 0 0 0\n2 1 0 0\n3 2 0 0\n4 2 1 0\n5 1 1 0\n6 0 1 0\n\
    7 0.5 0 0\n8 1.5 0 0\n9 2 0.5 0\n10 1.5 1 0\n11 0.5 1 0\n12 0 0.5 0\n13 1 0.5 0\n";
/// Element A's and element B's node tags, Gmsh order.
const A: &str = "1 2 5 6 7 13 11 12";
const B: &str = "2 3 4 5 8 9 10 13";

/// Format 2.2: A in "stiff"; B in "soft" and, repeated under a new tag, in "stiff".
fn two_surfaces_v22() -> String {
    format!(
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n\
         $PhysicalNames\n2\n2 1 \"stiff\"\n2 2 \"soft\"\n$EndPhysicalNames\n\
         $Nodes\n{NODES_22}$EndNodes\n\
         $Elements\n3\n1 16 2 1 1 {A}\n2 16 2 2 2 {B}\n3 16 2 1 2 {B}\n$EndElements\n"
    )
}

/// Format 4.1: A on surface 1 (physical "stiff"), B on surface 2 (physicals "soft", then
/// "stiff", in that order in `$Entities`).
fn two_surfaces_v41() -> String {
    let coords: String =
        NODES_22.lines().skip(1).map(|l| l.split_once(' ').unwrap().1.to_string() + "\n").collect();
    let tags: String = (1..=13).map(|t| format!("{t}\n")).collect();
    format!(
        "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n\
         $PhysicalNames\n2\n2 1 \"stiff\"\n2 2 \"soft\"\n$EndPhysicalNames\n\
         $Entities\n0 0 2 0\n1 0 0 0 1 1 0 1 1 0\n2 1 0 0 2 1 0 2 2 1 0\n$EndEntities\n\
         $Nodes\n1 13 1 13\n2 1 0 13\n{tags}{coords}$EndNodes\n\
         $Elements\n2 2 1 2\n2 1 16 1\n1 {A}\n2 2 16 1\n2 {B}\n$EndElements\n"
    )
}

/// Both formats read both surfaces of the element in two of them, in file order, and the
/// mesh built from either has element sets "stiff" = {A, B} and "soft" = {B} (exact: index
/// sets).
#[test]
fn physical_surfaces_become_element_sets_in_both_formats() {
    for (format, text) in [("2.2", two_surfaces_v22()), ("4.1", two_surfaces_v41())] {
        let raw = parse_msh(&text).unwrap_or_else(|e| panic!("{format}: {e}"));
        assert_eq!(raw.elements.len(), 2, "{format}: the repeated element is read once");
        assert_eq!(raw.elements[0].physicals, ["stiff"], "{format}");
        assert_eq!(raw.elements[1].physicals, ["soft", "stiff"], "{format}");
        let mesh = Mesh::from_description(MeshDescription::from(raw)).unwrap();
        assert_eq!(mesh.n_elements(), 2, "{format}");
        assert_eq!(mesh.element_set("stiff").unwrap(), [0, 1], "{format}");
        assert_eq!(mesh.element_set("soft").unwrap(), [1], "{format}");
        assert_eq!(mesh.element_sets.len(), 2, "{format}");
    }
}

/// An unknown element set is an error naming it and the known ones; a structured mesh has
/// no element sets.
#[test]
fn unknown_element_set_names_the_known_ones() {
    let raw = parse_msh(&two_surfaces_v22()).unwrap();
    let mesh = Mesh::from_description(MeshDescription::from(raw)).unwrap();
    let msg = mesh.element_set("rock").unwrap_err().to_string();
    assert!(msg.contains("rock") && msg.contains("soft, stiff"), "{msg}");
    let rect = Mesh::rectangle(ElementKind::Q8, 1.0, 1.0, 2, 2, [0.0, 0.0]).unwrap();
    assert!(rect.element_sets.is_empty());
    assert!(rect.element_set("stiff").is_err());
}

/// Element groups are sorted and made unique; an index past the last element is refused
/// with the group's name and the index.
#[test]
fn element_groups_are_checked_sorted_and_unique() {
    let raw = parse_msh(&two_surfaces_v22()).unwrap();
    let mut desc = MeshDescription::from(raw);
    desc.element_groups = BTreeMap::from([("both".to_string(), vec![1, 0, 1])]);
    let mesh = Mesh::from_description(desc.clone()).unwrap();
    assert_eq!(mesh.element_set("both").unwrap(), [0, 1]);

    desc.element_groups = BTreeMap::from([("far".to_string(), vec![0, 2])]);
    let msg = Mesh::from_description(desc).unwrap_err().to_string();
    assert!(msg.contains("element_groups") && msg.contains("far") && msg.contains('2'), "{msg}");
}
