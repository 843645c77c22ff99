//! From the job to the solver's own types: the FE [`Model`](cosdem_fem::solve::Model) (mesh, field, Gauss rule,
//! loading), the [`SolverSettings`] and the elastic material. Nothing past this module knows
//! about the job file.

use crate::schema::{
    ComponentChoice, Continuum, ControlSection, ElementChoice, Integration, Job, MaterialSection,
    MeshKind, Moving, PlatenChoice, RampChoice,
};
use cosdem_fem::assembly::{Component, Field};
use cosdem_fem::element::{ElementKind, QuadratureRule};
use cosdem_fem::error::{Error, Result};
use cosdem_fem::gmsh;
use cosdem_fem::material::ElasticCosserat;
use cosdem_fem::mesh::{Mesh, MeshDescription};
use cosdem_fem::solve::{
    Dirichlet, EdgeLoad, EdgeLoadKind, Loading, Platens, Ramp, SolverSettings,
};
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;

impl From<ComponentChoice> for Component {
    fn from(c: ComponentChoice) -> Self {
        match c {
            ComponentChoice::Ux => Component::Ux,
            ComponentChoice::Uy => Component::Uy,
            ComponentChoice::W => Component::W,
        }
    }
}

impl MaterialSection {
    /// The linear-elastic Cosserat material of an `elastic` section (its defaults filled in:
    /// Gc = G / 2, lc = 0.01 m); `None` for a DEM one.
    pub fn elastic(&self) -> Option<ElasticCosserat> {
        match self {
            MaterialSection::Elastic { shear_modulus, poisson, cosserat_modulus, length } => {
                let g = *shear_modulus;
                Some(ElasticCosserat::new(
                    g,
                    *poisson,
                    cosserat_modulus.unwrap_or(0.5 * g),
                    length.unwrap_or(0.01),
                ))
            }
            MaterialSection::Dem { .. } => None,
        }
    }
}

impl Job {
    /// The linear-elastic Cosserat material of an `elastic` job's `[material]` (its defaults
    /// filled in: Gc = G / 2, lc = 0.01 m); `None` for a DEM job. A region's is
    /// [`MaterialSection::elastic`] of its section.
    pub fn elastic(&self) -> Option<ElasticCosserat> {
        self.material.elastic()
    }

    /// The continuum field.
    pub fn field(&self) -> Field {
        match self.mesh.continuum {
            Continuum::Cosserat => Field::Cosserat,
            Continuum::Cauchy => Field::Cauchy,
        }
    }

    /// Builds the mesh (reads the Gmsh file if any).
    pub fn build_mesh(&self) -> Result<Mesh> {
        let m = &self.mesh;
        match m.kind {
            MeshKind::Rectangle => {
                let kind = match m.element {
                    ElementChoice::Q8 => ElementKind::Q8,
                    ElementChoice::Q9 => ElementKind::Q9,
                    ElementChoice::T6 => ElementKind::T6,
                };
                // validate() made sure these are present.
                let (lx, ly, nx, ny) = m.symmetry.reduce_rectangle(
                    m.lx.unwrap_or(1.0),
                    m.ly.unwrap_or(1.0),
                    m.nx.unwrap_or(1),
                    m.ny.unwrap_or(1),
                );
                Mesh::rectangle(kind, lx, ly, nx, ny, m.origin)
            }
            MeshKind::Gmsh => {
                let file = m.file.as_deref().unwrap_or(Path::new(""));
                // The reader's and the mesh's errors name the file and the line; the key is
                // `mesh.file`.
                let bad = |reason: String| Error::InvalidSetting {
                    field: "mesh.file",
                    value: format!("{:?}", file.display().to_string()),
                    reason,
                };
                let raw = gmsh::read_msh(file).map_err(|e| bad(e.to_string()))?;
                Mesh::from_description(MeshDescription::from(raw)).map_err(|e| bad(e.to_string()))
            }
        }
    }

    /// The loading of the job: compression platens, prescribed dofs and pressures.
    pub fn loading(&self) -> Loading {
        let l = &self.loading;
        let mut loading = match &l.compression {
            Some(c) => {
                let platens = match c.platens {
                    PlatenChoice::Rough => Platens::Rough,
                    PlatenChoice::Smooth => Platens::Smooth,
                };
                let (top, bottom) = match c.moving {
                    Moving::Both => (-0.5 * c.displacement, 0.5 * c.displacement),
                    Moving::Top => (-c.displacement, 0.0),
                };
                Loading::compression(top, bottom, platens)
            }
            None => Loading::default(),
        };
        for p in &l.prescribed {
            loading.dirichlet.push(Dirichlet::new(&p.set, p.component.into(), p.value));
        }
        for p in &l.pressure {
            let ramp = match p.ramp {
                RampChoice::Constant => Ramp::Constant,
                RampChoice::Linear => Ramp::Linear,
            };
            loading.edge_loads.push(EdgeLoad {
                set: p.set.clone(),
                kind: EdgeLoadKind::Pressure(p.value),
                ramp,
            });
        }
        loading.control = l.control.as_ref().map(ControlSection::path_control);
        self.mesh.symmetry.reduce_loading(loading, self.field())
    }

    /// Factor from the meshed part's reaction to the whole panel's load (2 on a half or
    /// quarter mesh).
    pub fn load_scale(&self) -> f64 {
        self.mesh.symmetry.load_scale()
    }

    /// Total shortening of the compression (m), 0 without one: the curve's abscissa is
    /// `load_factor * shortening`.
    pub fn shortening(&self) -> f64 {
        self.loading.compression.as_ref().map_or(0.0, |c| c.displacement)
    }

    /// The Gauss rule of `integration` on elements of `kind`: 2x2 (`reduced`) or 3x3 (`full`)
    /// points on a quadrilateral, 3 or 6 on a triangle. A mixed mesh's other family takes the
    /// rule of the same role ([`QuadratureRule::on`]).
    pub fn rule(&self, kind: ElementKind) -> QuadratureRule {
        QuadratureRule::for_kind(kind, self.mesh.integration == Integration::Full)
    }

    /// The FE model: mesh, field, rule, loading. Checks the sets the job names and the
    /// regions ([`Job::element_materials`]) against the mesh.
    pub fn model(&self) -> Result<cosdem_fem::solve::Model> {
        let mesh = self.build_mesh()?;
        // Without `[output.curve]` the curve's load is the reaction of this set: a name the
        // mesh lacks would report a load of -0 at every step. With it, the set is not used.
        let load_set = &self.loading.load_set;
        if self.output.curve.is_none() && !mesh.node_sets.contains_key(load_set) {
            return Err(Error::InvalidSetting {
                field: "loading.load_set",
                value: load_set.clone(),
                reason: format!(
                    "the mesh has no node set of that name (known: {})",
                    mesh.node_sets.keys().cloned().collect::<Vec<_>>().join(", ")
                ),
            });
        }
        if let Some(curve) = &self.output.curve {
            curve.check_sets(&mesh)?;
        }
        self.check_stage_sets(&mesh)?;
        if let Some(c) = &self.loading.control {
            check_control("loading.control", c, &mesh)?;
        }
        // A bad region is refused here, before anything runs.
        let element_materials = self.element_materials(&mesh)?;
        let loading = match self.is_staged() {
            true => {
                let map = (!self.region.is_empty()).then(|| Arc::new(element_materials));
                self.stages_with(map)?.swap_remove(0).loading
            }
            false => self.loading(),
        };
        let rule = self.rule(mesh.element_kind(0));
        Ok(cosdem_fem::solve::Model {
            mesh,
            field: self.field(),
            rule,
            loading,
            kinematics: self.mesh.kinematics,
        })
    }

    /// Newton and step settings.
    pub fn solver_settings(&self) -> Result<SolverSettings> {
        let l = &self.loading;
        let steps = match (l.increment, &l.compression, self.stage.first()) {
            (_, _, Some(first)) => first.steps,
            (Some(inc), Some(c), None) => SolverSettings::steps_for_increment(c.displacement, inc)?,
            _ => l.steps,
        };
        let n = &self.newton;
        Ok(SolverSettings {
            steps,
            max_iterations: n.max_iterations,
            force_tolerance: n.force_tolerance,
            displacement_tolerance: n.displacement_tolerance,
            line_search: n.line_search,
            min_increment_fraction: n.min_increment_fraction,
            tolerated_residual: n.tolerated_residual,
            secant_updates: n.secant_updates,
            stall_iterations: n.stall_iterations,
            forced_residual: n.forced_residual,
            ..SolverSettings::default()
        })
    }
}

/// `Ok` when `set` names a non-empty set among `sets` (the mesh's node or edge sets, `kind`
/// `"node"` or `"edge"`); else the error naming `field`, the value and the sets there are.
pub(crate) fn require_set<T>(
    field: &'static str,
    set: &str,
    kind: &str,
    sets: &BTreeMap<String, Vec<T>>,
) -> Result<()> {
    if sets.get(set).is_some_and(|s| !s.is_empty()) {
        return Ok(());
    }
    Err(Error::InvalidSetting {
        field,
        value: set.to_string(),
        reason: format!(
            "the mesh has no non-empty {kind} set of that name (known: {})",
            sets.keys().map(String::as_str).collect::<Vec<_>>().join(", ")
        ),
    })
}

/// A path control's node set must be a non-empty set of the mesh and its value finite and
/// not zero (`at`: the control's key, `loading.control` or `stage[i].control`).
pub(crate) fn check_control(at: &str, c: &ControlSection, mesh: &Mesh) -> Result<()> {
    let field = |rest: &str| crate::validate::interned(format!("{at}.{rest}"));
    require_set(field("set"), &c.set, "node", &mesh.node_sets)?;
    if !(c.value.is_finite() && c.value != 0.0) {
        return Err(Error::InvalidSetting {
            field: field("value"),
            value: c.value.to_string(),
            reason: "must be finite and not zero (the control quantity's change)".into(),
        });
    }
    for (j, t) in c.plus.iter().enumerate() {
        require_set(field(&format!("plus[{j}].set")), &t.set, "node", &mesh.node_sets)?;
        if !t.weight.is_finite() {
            return Err(Error::InvalidSetting {
                field: field(&format!("plus[{j}].weight")),
                value: t.weight.to_string(),
                reason: "must be finite".into(),
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use crate::{Continuum, ElementChoice, Integration, Job, fixtures};
    use cosdem_fem::assembly::Component;

    fn minimal() -> Job {
        fixtures::load("elastic-panel")
    }

    #[test]
    fn minimal_job_takes_the_documented_defaults() {
        let job = minimal();
        assert_eq!(job.mesh.element, ElementChoice::Q8);
        assert_eq!(job.mesh.integration, Integration::Reduced);
        assert_eq!(job.mesh.continuum, Continuum::Cosserat);
        assert_eq!(job.output.vtk_every, 1);
        assert_eq!(job.loading.load_set, "top");
        let model = job.model().unwrap();
        assert_eq!(model.mesh.n_elements(), 4);
        assert_eq!(job.solver_settings().unwrap().steps, 4);
    }

    /// The curve's load is the reaction of `load_set`: a name the mesh lacks is refused naming
    /// the key, the value and the sets the mesh has (it used to report a load of -0).
    #[test]
    fn an_unknown_load_set_is_refused_naming_the_key() {
        let mut job = minimal();
        job.loading.load_set = "nosuch".into();
        let e = job.model().unwrap_err();
        assert!(
            matches!(&e, cosdem_fem::Error::InvalidSetting { field: "loading.load_set", value, .. }
                if value == "nosuch"),
            "{e}"
        );
        assert!(e.to_string().contains("known: ") && e.to_string().contains("top"), "{e}");
        job.loading.load_set = "bottom".into();
        job.model().unwrap();
    }

    /// With `[output.curve]` the curve names its own sets and `loading.load_set` (default
    /// `top`) is not used: a mesh without that set is not refused for it (a Gmsh footing mesh
    /// without `top` was), while a curve set the mesh lacks still is.
    #[test]
    fn load_set_is_not_checked_when_the_curve_names_its_sets() {
        let text = format!(
            "{}\n[output.curve]\ncontrol = {{ set = \"bottom\", component = \"uy\" }}\nload = {{ set = \"bottom\", component = \"uy\" }}\n",
            fixtures::text("elastic-panel")
        );
        let mut job = Job::from_toml(&text, "j.toml").unwrap();
        job.loading.load_set = "nosuch".into();
        job.model().unwrap();
        job.output.curve.as_mut().unwrap().load.set = "nosuch".into();
        let e = job.model().unwrap_err().to_string();
        assert!(e.contains("nosuch"), "{e}");
    }

    #[test]
    fn increment_gives_the_number_of_steps() {
        let text = fixtures::text("elastic-panel").replace("steps = 4", "increment = 0.001");
        let job = Job::from_toml(&text, "j").unwrap();
        assert_eq!(job.solver_settings().unwrap().steps, 10);
    }

    #[test]
    fn symmetric_compression_moves_both_platens_by_half() {
        let l = minimal().loading();
        let top = l.dirichlet.iter().find(|d| d.set == "top" && d.component == Component::Uy);
        let bottom = l.dirichlet.iter().find(|d| d.set == "bottom" && d.component == Component::Uy);
        assert_eq!(top.unwrap().value, -0.005);
        assert_eq!(bottom.unwrap().value, 0.005);
    }
}
