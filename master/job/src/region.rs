//! `[[region]]`: parts of the mesh with their own material (and bulk density for gravity).
//!
//! A region names its elements either by a Gmsh physical surface (`physical`, an element set
//! of the mesh) or by inclusive 0-based ranges of element indices (`elements`, any mesh; the
//! indices are those of the mesh as built, so of the half or quarter with `mesh.symmetry`).
//! Every element is in at most one region; an element in none takes `[material]`. Materials are
//! numbered 0 for `[material]` and `i + 1` for `region[i]` ([`Job::materials`],
//! [`Job::element_materials`]).
//!
//! Gravity per region: an element of a region with `bulk_density` weighs that density times
//! the stage's acceleration, every other element the stage's `density`
//! ([`Job::body_forces`] and [`body_load`], used by the stages).

use crate::schema::{Job, MaterialSection, MeshKind};
use crate::stage::StageGravity;
use crate::validate::interned;
use cosdem_fem::error::{Error, Result};
use cosdem_fem::mesh::Mesh;
use cosdem_fem::solve::BodyLoad;
use serde::{Deserialize, Deserializer, Serialize};
use std::sync::Arc;

/// `[[region]]`: a part of the mesh with its own material.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RegionSection {
    /// Free text: the region's name in messages and logs (`region[0] (sand)`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// The Gmsh physical surface whose elements form the region (exclusive with `elements`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub physical: Option<String>,
    /// Inclusive 0-based ranges `[first, last]` of element indices (exclusive with `physical`).
    #[serde(default, deserialize_with = "ranges", skip_serializing_if = "Vec::is_empty")]
    pub elements: Vec<[usize; 2]>,
    /// The region's material, with the keys of `[material]`.
    pub material: MaterialSection,
    /// Bulk density (kg/m^3) of the region's gravity, instead of the stage's `density`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bulk_density: Option<f64>,
}

/// `elements`: a list of pairs `[first, last]`, each exactly two numbers (serde's `[T; 2]`
/// would ignore a third).
fn ranges<'de, D: Deserializer<'de>>(d: D) -> std::result::Result<Vec<[usize; 2]>, D::Error> {
    let lists = Vec::<Vec<usize>>::deserialize(d)?;
    lists
        .iter()
        .enumerate()
        .map(|(k, pair)| {
            <[usize; 2]>::try_from(pair.as_slice()).map_err(|_| {
                serde::de::Error::custom(format!(
                    "`elements[{k}]` takes 2 numbers [first, last], found {}",
                    pair.len()
                ))
            })
        })
        .collect()
}

fn bad(field: &'static str, value: impl Into<String>, reason: impl Into<String>) -> Error {
    Error::InvalidSetting { field, value: value.into(), reason: reason.into() }
}

/// The key `region[i]` followed by `rest` (`.physical`, `.elements[0]`).
fn key(i: usize, rest: &str) -> &'static str {
    interned(format!("region[{i}]{rest}"))
}

/// The body force of stage gravity per material, `[rho g_x, rho g_y]` at index 0 for
/// `[material]`, `i + 1` for `region[i]` (see [`Job::body_forces`]), as one closure over the
/// elements: `element_materials` maps an element to its material; `None` (a job without
/// regions, one material) gives every element the first force.
pub(crate) fn body_load(
    forces: Vec<[f64; 2]>,
    element_materials: Option<Arc<Vec<usize>>>,
) -> BodyLoad {
    match element_materials {
        None => {
            let f = forces[0];
            BodyLoad::new(move |_, _| [f[0], f[1], 0.0])
        }
        Some(map) => BodyLoad::new(move |e, _| {
            let f = forces[map[e]];
            [f[0], f[1], 0.0]
        }),
    }
}

impl Job {
    /// The materials, numbered as [`Job::element_materials`] numbers them: `[material]` first,
    /// then the regions' in the file's order.
    pub fn materials(&self) -> Vec<&MaterialSection> {
        std::iter::once(&self.material).chain(self.region.iter().map(|r| &r.material)).collect()
    }

    /// Material `i` as messages name it: `material` for `[material]`, `region[0] (sand)` (or
    /// `region[0]` without a name) for region 0, and so on.
    pub fn material_label(&self, i: usize) -> String {
        match i {
            0 => "material".to_string(),
            _ => match self.region.get(i - 1).and_then(|r| r.name.as_deref()) {
                Some(name) => format!("region[{}] ({name})", i - 1),
                None => format!("region[{}]", i - 1),
            },
        }
    }

    /// The material of every element of `mesh`: 0 for `[material]` (an element in no region),
    /// `i + 1` for `region[i]`. Errors name the key and the value: a region with both or
    /// neither of `physical` and `elements`, a physical surface the mesh lacks (listing those
    /// it has), a range reversed or past the mesh's last element, a region without elements,
    /// an element in two regions (naming both and the element).
    pub fn element_materials(&self, mesh: &Mesh) -> Result<Vec<usize>> {
        let n = mesh.n_elements();
        let mut of = vec![0usize; n];
        for (i, r) in self.region.iter().enumerate() {
            self.check_region_shape(i, r)?;
            // (the key the elements come from, the elements).
            let mut parts: Vec<(&'static str, Vec<usize>)> = Vec::new();
            if let Some(name) = &r.physical {
                let Some(set) = mesh.element_sets.get(name) else {
                    let known: Vec<&str> = mesh.element_sets.keys().map(String::as_str).collect();
                    return Err(bad(
                        key(i, ".physical"),
                        format!("{name:?}"),
                        format!(
                            "the mesh has no physical surface (element set) of that name (known: {})",
                            if known.is_empty() { "none".to_string() } else { known.join(", ") }
                        ),
                    ));
                };
                parts.push((key(i, ".physical"), set.clone()));
            }
            for (k, &[first, last]) in r.elements.iter().enumerate() {
                if last >= n {
                    return Err(bad(
                        key(i, &format!(".elements[{k}]")),
                        format!("[{first}, {last}]"),
                        format!(
                            "past the mesh's last element: it has {n}, numbered 0 to {}",
                            n - 1
                        ),
                    ));
                }
                parts.push((key(i, &format!(".elements[{k}]")), (first..=last).collect()));
            }
            if parts.iter().all(|(_, elements)| elements.is_empty()) {
                let value = r.physical.as_ref().map_or_else(String::new, |p| format!("{p:?}"));
                return Err(bad(key(i, ".physical"), value, "the region has no elements"));
            }
            for (at, elements) in parts {
                for e in elements {
                    match of[e] {
                        0 => of[e] = i + 1,
                        m if m == i + 1 => {}
                        m => {
                            return Err(bad(
                                at,
                                format!("element {e}"),
                                format!(
                                    "element {e} is also in {}: an element is in at most one region",
                                    self.material_label(m)
                                ),
                            ));
                        }
                    }
                }
            }
        }
        Ok(of)
    }

    /// The checks of `region[i]` that need no mesh: exactly one of `physical` and a non-empty
    /// `elements`, no `physical` on a structured rectangle, and ranges in order.
    fn check_region_shape(&self, i: usize, r: &RegionSection) -> Result<()> {
        match (&r.physical, r.elements.is_empty()) {
            (Some(p), false) => {
                return Err(bad(
                    key(i, ".physical"),
                    format!("{p:?}"),
                    "given with `elements`: a region takes exactly one of physical and elements",
                ));
            }
            (None, true) => {
                return Err(bad(
                    key(i, ""),
                    "neither physical nor elements",
                    "a region takes exactly one of physical (a Gmsh physical surface) and elements (ranges [first, last])",
                ));
            }
            (Some(p), true) if self.mesh.kind == MeshKind::Rectangle => {
                return Err(bad(
                    key(i, ".physical"),
                    format!("{p:?}"),
                    "a structured rectangle has no physical surfaces: give elements ranges",
                ));
            }
            _ => {}
        }
        for (k, &[first, last]) in r.elements.iter().enumerate() {
            if first > last {
                return Err(bad(
                    key(i, &format!(".elements[{k}]")),
                    format!("[{first}, {last}]"),
                    "reversed: a range is [first, last] with first <= last (inclusive, from 0)",
                ));
            }
        }
        Ok(())
    }

    /// Checks `[[region]]` without the mesh: each region's shape and bulk density, and no
    /// `accuracy` target (it plans one material). The regions' materials are checked with
    /// `[material]`'s checks by `validate`.
    pub(crate) fn validate_regions(&self) -> Result<()> {
        if self.region.is_empty() {
            return Ok(());
        }
        if let Some(a) = self.accuracy {
            return Err(bad(
                "accuracy",
                format!("{a:?}"),
                "an accuracy target plans the one material of [material]; [[region]] gives several",
            ));
        }
        for (i, r) in self.region.iter().enumerate() {
            self.check_region_shape(i, r)?;
            if let Some(rho) = r.bulk_density
                && !(rho.is_finite() && rho > 0.0)
            {
                return Err(bad(
                    key(i, ".bulk_density"),
                    format!("{rho:?}"),
                    "must be finite and > 0 (kg/m^3)",
                ));
            }
        }
        Ok(())
    }

    /// Whether the stages' gravity may leave out `density`: every region gives a
    /// `bulk_density` or is DEM (weighed from its assembly), and `[material]` is DEM or every
    /// region gives one (then the regions must cover the mesh: checked when the stages are
    /// built, where the elements are known).
    pub(crate) fn weighs_without_stage_density(&self) -> bool {
        let dem = |m: &MaterialSection| matches!(m, MaterialSection::Dem { .. });
        let regions = self.region.iter().all(|r| r.bulk_density.is_some() || dem(&r.material));
        let all_given =
            !self.region.is_empty() && self.region.iter().all(|r| r.bulk_density.is_some());
        regions && (dem(&self.material) || all_given)
    }

    /// The body force `[rho g_x, rho g_y]` of stage `i`'s gravity `g` per material (index as in
    /// [`Job::materials`]): `rho` is the region's `bulk_density`, else the stage's `density`,
    /// else for a DEM material its assembly's solid density times solid fraction
    /// ([`crate::bulk`]).
    /// `element_materials` ([`Job::element_materials`]) tells which materials are used: a used
    /// one without a density is an error naming `stage[i].gravity.density`; an unused one
    /// gets no force. Without regions, one force, `[density g_x, density g_y]`.
    pub(crate) fn body_forces(
        &self,
        i: usize,
        g: &StageGravity,
        element_materials: Option<&[usize]>,
    ) -> Result<Vec<[f64; 2]>> {
        let densities = std::iter::once(None).chain(self.region.iter().map(|r| r.bulk_density));
        let mut forces = Vec::with_capacity(1 + self.region.len());
        for (m, own) in densities.enumerate() {
            let used = element_materials.is_none_or(|map| map.contains(&m));
            let rho = match (own, g.density, self.materials()[m]) {
                (Some(rho), _, _) | (None, Some(rho), _) => rho,
                (None, None, _) if !used => 0.0,
                (None, None, MaterialSection::Dem { assembly }) => {
                    crate::bulk::assembly_bulk_density(assembly).map_err(|e| {
                        bad(
                            interned(format!("stage[{i}].gravity.density")),
                            "missing",
                            format!(
                                "the bulk density of {} from its assembly: {e}",
                                self.material_label(m)
                            ),
                        )
                    })?
                }
                (None, None, MaterialSection::Elastic { .. }) => {
                    return Err(bad(
                        interned(format!("stage[{i}].gravity.density")),
                        "missing",
                        format!(
                            "{} is elastic and has no bulk_density: a body force needs the material's bulk density (kg/m^3)",
                            self.material_label(m)
                        ),
                    ));
                }
            };
            forces.push([rho * g.acceleration[0], rho * g.acceleration[1]]);
        }
        Ok(forces)
    }
}

#[cfg(test)]
mod tests {
    use crate::{Job, fixtures};

    /// The elastic panel (2 x 2 elements) with `regions` appended.
    fn panel_with(regions: &str) -> Result<Job, String> {
        let text = format!("{}\n{regions}\n", fixtures::text("elastic-panel"));
        Job::from_toml(&text, "j").map_err(|e| e.to_string())
    }

    const REGION: &str = "[[region]]\nname = \"soft\"\nelements = [[0, 1]]\n\
                          [region.material]\nkind = \"elastic\"\nshear_modulus = 1e6\npoisson = 0.2\n";

    /// Materials are numbered `[material]` then regions, and labelled with the region's name.
    #[test]
    fn materials_are_numbered_and_labelled() {
        let job = panel_with(REGION).unwrap();
        assert_eq!(job.materials().len(), 2);
        assert_eq!(job.materials()[1], &job.region[0].material);
        assert_eq!(job.material_label(0), "material");
        assert_eq!(job.material_label(1), "region[0] (soft)");
        let mut unnamed = job.clone();
        unnamed.region[0].name = None;
        assert_eq!(unnamed.material_label(1), "region[0]");
        let mesh = job.build_mesh().unwrap();
        assert_eq!(job.element_materials(&mesh).unwrap(), [1, 1, 0, 0]);
    }

    /// A region's material gets `[material]`'s checks with its own key; the shape checks that
    /// need no mesh, and `accuracy`, are refused at validation naming the key and the value.
    #[test]
    fn bad_regions_are_refused_at_validation() {
        for (text, key, value) in [
            (REGION.replace("poisson = 0.2", "poisson = 0.7"), "region[0].material.poisson", "0.7"),
            (
                REGION.replace("shear_modulus = 1e6", "shear_modulus = -1.0"),
                "region[0].material.shear_modulus",
                "-1.0",
            ),
            (REGION.replace("[[0, 1]]", "[[3, 1]]"), "region[0].elements[0]", "[3, 1]"),
            (REGION.replace("elements = [[0, 1]]", ""), "region[0]", "neither"),
            (REGION.replace("elements = [[0, 1]]", "elements = []"), "region[0]", "neither"),
            (
                REGION.replace("elements = [[0, 1]]", "physical = \"sand\""),
                "region[0].physical",
                "structured",
            ),
            (REGION.replace("name", "physical = \"x\"\nname"), "region[0].physical", "exactly one"),
            (REGION.replace("name", "bulk_density = -2.0\nname"), "region[0].bulk_density", "-2.0"),
            (REGION.replace("[[0, 1]]", "[[0, 1, 2]]"), "elements[0]", "2 numbers"),
            (REGION.replace("name", "colour = 1\nname"), "colour", ""),
        ] {
            let err = panel_with(&text).unwrap_err();
            assert!(err.contains(key) && err.contains(value), "{key}: {err}");
        }
        let dem = fixtures::text("dem-one-element");
        let region = "[[region]]\nelements = [[0, 0]]\n[region.material]\nkind = \"dem\"\n\
                      [region.material.assembly]\ndensity = -5.0\n";
        let err = Job::from_toml(&format!("{dem}\n{region}"), "j").unwrap_err().to_string();
        assert!(
            err.contains("region[0].material.assembly.density") && err.contains("-5.0"),
            "{err}"
        );
        let err = Job::from_toml(
            &format!("accuracy = 0.05\n{dem}\n{}", region.replace("density = -5.0", "")),
            "j",
        )
        .unwrap_err()
        .to_string();
        assert!(err.contains("accuracy") && err.contains("[[region]]"), "{err}");
    }

    /// A job without regions writes no `region` key (its serialization and digest are as
    /// before); one with regions reads back the same.
    #[test]
    fn regions_are_written_only_when_given() {
        let job = fixtures::load("elastic-panel");
        assert!(!toml::to_string(&job).unwrap().contains("region"));
        let job = panel_with(&REGION.replace("name", "bulk_density = 1800.0\nname")).unwrap();
        let text = toml::to_string(&job).unwrap();
        assert_eq!(Job::from_toml(&text, "j").unwrap(), job, "{text}");
    }
}
