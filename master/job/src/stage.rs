//! `[[stage]]`: a job's loading as a list of stages, and what each stage hands the solver.
//!
//! A stage moves node sets (a target, an increment, or a path of targets), applies, holds or
//! removes pressures, tractions and gravity, in its own number of steps, possibly repeated.
//! What an earlier stage set stays in force until a later one changes it:
//! - a prescribed dof is held where the last stage left it (`free = true` releases it);
//! - a pressure or traction stays at its value (a new value is reached over the stage with
//!   `ramp = "linear"`, at once with `"constant"`; `"remove"` takes it away over the stage);
//! - gravity likewise (`[stage.gravity]`, with the same ramps).
//!
//! A job without `[[stage]]` is the one stage of its `[loading]`, exactly as before stages.
//! Keys in errors name a stage by its index in the file, from 0: `stage[1].prescribed[0].set`.

use crate::region::body_load;
use crate::schema::{ComponentChoice, Job};
use crate::validate::interned;
use cosdem_fem::assembly::Component;
use cosdem_fem::error::{Error, Result};
use cosdem_fem::mesh::Mesh;
use cosdem_fem::solve::{Dirichlet, EdgeLoad, EdgeLoadKind, Loading, Ramp};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::sync::Arc;

/// Most stages a job expands to (repetitions and path points counted): a cyclic test of a
/// few hundred cycles fits; a typo of `repeat = 1e9` does not.
pub const MAX_STAGES: usize = 100_000;

/// How a load of a stage follows the stage's load factor.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StageRamp {
    /// Full from the stage's first step (default).
    Constant,
    /// From its value before the stage (0 if none) to the new value over the stage.
    Linear,
    /// From its value before the stage to zero over the stage.
    Remove,
}

fn default_ramp() -> StageRamp {
    StageRamp::Constant
}

/// `[[stage.prescribed]]`: a dof of a node set in this stage.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StagePrescribed {
    /// Node set.
    pub set: String,
    /// `ux`, `uy` or `w`.
    pub component: ComponentChoice,
    /// The value reached at the end of the stage (m or rad).
    pub value: Option<f64>,
    /// The change over the stage from where the dofs are (negative to unload; 0 holds).
    pub increment: Option<f64>,
    /// Targets reached one after the other, each over `steps` steps (a path table: a cyclic
    /// loading is `[a, b, a, b]`); the stage becomes one stage per target.
    #[serde(default)]
    pub path: Vec<f64>,
    /// Releases the dof prescribed by an earlier stage.
    #[serde(default)]
    pub free: bool,
}

/// `[[stage.pressure]]`: a pressure on an edge set.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StagePressure {
    /// Edge set.
    pub set: String,
    /// Pressure (Pa, positive pushes into the body); not needed with `ramp = "remove"`.
    #[serde(default)]
    pub value: f64,
    /// `constant` (default), `linear` or `remove`.
    #[serde(default = "default_ramp")]
    pub ramp: StageRamp,
}

/// `[[stage.traction]]`: a traction vector on an edge set.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StageTraction {
    /// Edge set.
    pub set: String,
    /// `[t_x, t_y]` (Pa); not needed with `ramp = "remove"`.
    #[serde(default)]
    pub value: [f64; 2],
    /// `constant` (default), `linear` or `remove`.
    #[serde(default = "default_ramp")]
    pub ramp: StageRamp,
}

/// `[stage.gravity]`: self-weight, the bulk density times the acceleration.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StageGravity {
    /// Acceleration `[g_x, g_y]` (m/s^2), e.g. `[0, -9.81]`.
    pub acceleration: [f64; 2],
    /// Bulk density of the material (kg/m^3 of the continuum: the solid density times the
    /// solid fraction for a dry granular material); an element of a `[[region]]` with
    /// `bulk_density` takes the region's instead. Left out, a DEM material weighs its
    /// assembly's solid density times solid fraction ([`crate::bulk`]); an elastic one needs
    /// its region's `bulk_density`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density: Option<f64>,
    /// `constant` (default), `linear` or `remove`.
    #[serde(default = "default_ramp")]
    pub ramp: StageRamp,
}

/// `[[stage]]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StageSection {
    /// Free text (logs).
    #[serde(default)]
    pub name: String,
    /// Equal load steps of the stage (default 10).
    #[serde(default = "default_steps")]
    pub steps: usize,
    /// The stage this many times in a row (default 1): with increments, a cyclic loading.
    #[serde(default = "one")]
    pub repeat: usize,
    /// Prescribed dofs.
    #[serde(default)]
    pub prescribed: Vec<StagePrescribed>,
    /// Pressures.
    #[serde(default)]
    pub pressure: Vec<StagePressure>,
    /// Tractions.
    #[serde(default)]
    pub traction: Vec<StageTraction>,
    /// Self-weight.
    pub gravity: Option<StageGravity>,
}

fn default_steps() -> usize {
    10
}
fn one() -> usize {
    1
}

/// One stage as the solver runs it.
#[derive(Clone, Debug)]
pub struct SolverStage {
    /// The stage's loading (what is held from earlier stages included).
    pub loading: Loading,
    /// Its nominal steps.
    pub steps: usize,
    /// Its name, with the repetition or path point (`unload`, `cycle 3/10`).
    pub name: String,
}

/// What an edge load is, for the bookkeeping of loads in force.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Edge {
    Pressure(f64),
    Traction([f64; 2]),
}

impl Edge {
    fn kind(self) -> EdgeLoadKind {
        match self {
            Edge::Pressure(p) => EdgeLoadKind::Pressure(p),
            Edge::Traction(t) => EdgeLoadKind::Traction(t),
        }
    }
    fn minus(self, other: Edge) -> Edge {
        match (self, other) {
            (Edge::Pressure(a), Edge::Pressure(b)) => Edge::Pressure(a - b),
            (Edge::Traction(a), Edge::Traction(b)) => Edge::Traction([a[0] - b[0], a[1] - b[1]]),
            _ => unreachable!("loads are kept per set and kind"),
        }
    }
}

/// Loads in force after the stages so far.
#[derive(Clone, Debug, Default)]
struct InForce {
    /// Prescribed (set, component), in the order first prescribed.
    held: Vec<(String, Component)>,
    /// Edge loads by (set, is traction).
    edges: BTreeMap<(String, bool), Edge>,
    /// Body force density `[f_x, f_y]` per material (as numbered by [`Job::materials`]).
    gravity: Option<Vec<[f64; 2]>>,
}

/// What a job's stages so far leave in force, for expanding its stages one at a time
/// ([`Job::next_stages`]).
#[derive(Clone, Debug, Default)]
pub struct StagesSoFar {
    /// Loads in force.
    force: InForce,
    /// `[[stage]]` entries expanded so far.
    count: usize,
    /// The material of every element, from the first stage with gravity on (with regions).
    element_materials: Option<Arc<Vec<usize>>>,
}

impl StagesSoFar {
    /// `[[stage]]` entries expanded so far: the index the next one's errors name.
    pub fn count(&self) -> usize {
        self.count
    }
}

fn component(c: ComponentChoice) -> Component {
    c.into()
}

fn key(i: usize, rest: &str) -> &'static str {
    interned(format!("stage[{i}]{rest}"))
}

fn bad(field: &'static str, value: impl Into<String>, reason: impl Into<String>) -> Error {
    Error::InvalidSetting { field, value: value.into(), reason: reason.into() }
}

impl Job {
    /// Whether the job is written in stages (`[[stage]]`).
    pub fn is_staged(&self) -> bool {
        !self.stage.is_empty()
    }

    /// The stages the solver runs, in order, repetitions and path points expanded; the
    /// first one's loading is the model's ([`Job::model`]). A job without `[[stage]]` is the
    /// one stage of its `[loading]`.
    ///
    /// With regions and gravity, the body force depends on the element's region: the mesh is
    /// built to find them ([`Job::element_materials`]).
    pub fn stages(&self) -> Result<Vec<SolverStage>> {
        let gravity = self.stage.iter().any(|s| s.gravity.is_some());
        let map = match !self.region.is_empty() && gravity {
            true => Some(Arc::new(self.element_materials(&self.build_mesh()?)?)),
            false => None,
        };
        self.stages_with(map)
    }

    /// [`Job::stages`] given the material of every element (`None` without regions).
    pub(crate) fn stages_with(
        &self,
        element_materials: Option<Arc<Vec<usize>>>,
    ) -> Result<Vec<SolverStage>> {
        if !self.is_staged() {
            let steps = self.solver_settings()?.steps;
            return Ok(vec![SolverStage { loading: self.loading(), steps, name: String::new() }]);
        }
        let mut out = Vec::new();
        let mut force = InForce::default();
        for (i, stage) in self.stage.iter().enumerate() {
            let more =
                self.expand_stage(i, stage, &mut force, element_materials.as_ref(), out.len())?;
            out.extend(more);
        }
        Ok(out)
    }

    /// The solver stages of `stage` when the stages before it are those of `so_far` (which
    /// is updated): what [`Job::stages`] gives for it in a job whose `[[stage]]` list is the
    /// stages so far followed by `stage`, by the same code, for a caller that gives a job's
    /// stages one at a time (the application's stepper) in constant time per stage. `stage`
    /// is checked as [`Job::validate`] checks a stage and its sets against `mesh`, the job's
    /// mesh (errors name `stage[i]...` keys, `i` = [`StagesSoFar::count`]); after an error
    /// `so_far` is as it was. The limit of [`MAX_STAGES`] applies to `stage`'s own
    /// expansion.
    pub fn next_stages(
        &self,
        stage: &StageSection,
        so_far: &mut StagesSoFar,
        mesh: &Mesh,
    ) -> Result<Vec<SolverStage>> {
        let i = so_far.count;
        self.validate_staged_job()?;
        self.validate_stage(i, stage)?;
        self.check_sets_of_stage(i, stage, mesh)?;
        let mut next = so_far.clone();
        if next.element_materials.is_none() && !self.region.is_empty() && stage.gravity.is_some() {
            next.element_materials = Some(Arc::new(self.element_materials(mesh)?));
        }
        let out =
            self.expand_stage(i, stage, &mut next.force, next.element_materials.as_ref(), 0)?;
        next.count += 1;
        *so_far = next;
        Ok(out)
    }

    /// The solver stages of stage `i` (repetitions and path points), given what is in force
    /// (updated) and `before` solver stages before it (for [`MAX_STAGES`]).
    fn expand_stage(
        &self,
        i: usize,
        stage: &StageSection,
        force: &mut InForce,
        element_materials: Option<&Arc<Vec<usize>>>,
        before: usize,
    ) -> Result<Vec<SolverStage>> {
        let mut out = Vec::new();
        let points = stage.prescribed.iter().map(|p| p.path.len()).max().unwrap_or(0);
        for r in 0..stage.repeat {
            for k in 0..points.max(1) {
                let loading = self.stage_loading(i, stage, k, force, element_materials)?;
                let mut name = stage.name.clone();
                if stage.repeat > 1 {
                    name = format!("{name} {}/{}", r + 1, stage.repeat);
                }
                if points > 1 {
                    name = format!("{name} point {}/{points}", k + 1);
                }
                out.push(SolverStage { loading, steps: stage.steps, name });
                if before + out.len() > MAX_STAGES {
                    return Err(bad(
                        key(i, ".repeat"),
                        stage.repeat.to_string(),
                        format!("the job expands to more than {MAX_STAGES} stages"),
                    ));
                }
            }
        }
        Ok(out)
    }

    /// The loading of stage `i` at path point `k`, given what is in force; updates it.
    fn stage_loading(
        &self,
        i: usize,
        stage: &StageSection,
        k: usize,
        force: &mut InForce,
        element_materials: Option<&Arc<Vec<usize>>>,
    ) -> Result<Loading> {
        let mut loading = Loading::default();
        // Held dofs first: the stage's own entries come later and win.
        let named: Vec<(String, Component)> =
            stage.prescribed.iter().map(|p| (p.set.clone(), component(p.component))).collect();
        for (set, c) in &force.held {
            if !named.contains(&(set.clone(), *c)) {
                loading.dirichlet.push(Dirichlet::increment(set, *c, 0.0));
            }
        }
        for p in &stage.prescribed {
            let c = component(p.component);
            let held = force.held.iter().position(|h| h.0 == p.set && h.1 == c);
            if p.free {
                if let Some(h) = held {
                    force.held.remove(h);
                }
                continue;
            }
            let d = if !p.path.is_empty() {
                Dirichlet::new(&p.set, c, p.path[k.min(p.path.len() - 1)])
            } else if let Some(v) = p.value {
                Dirichlet::new(&p.set, c, v)
            } else {
                Dirichlet::increment(&p.set, c, p.increment.unwrap_or(0.0))
            };
            loading.dirichlet.push(d);
            if held.is_none() {
                force.held.push((p.set.clone(), c));
            }
        }
        // Edge loads: those in force and not named are held.
        let mut named_edges = Vec::new();
        let news = stage
            .pressure
            .iter()
            .enumerate()
            .map(|(j, p)| {
                ((p.set.clone(), false), Edge::Pressure(p.value), p.ramp, format!(".pressure[{j}]"))
            })
            .chain(stage.traction.iter().enumerate().map(|(j, t)| {
                ((t.set.clone(), true), Edge::Traction(t.value), t.ramp, format!(".traction[{j}]"))
            }));
        let mut updates = Vec::new();
        for (id, new, ramp, at) in news {
            let old = force.edges.get(&id).copied();
            named_edges.push(id.clone());
            let mut push = |e: Edge, r: Ramp| {
                loading.edge_loads.push(EdgeLoad { set: id.0.clone(), kind: e.kind(), ramp: r })
            };
            match ramp {
                StageRamp::Constant => {
                    push(new, Ramp::Constant);
                    updates.push((id, Some(new)));
                }
                StageRamp::Linear => {
                    match old {
                        Some(o) => {
                            push(o, Ramp::Constant);
                            push(new.minus(o), Ramp::Linear);
                        }
                        None => push(new, Ramp::Linear),
                    }
                    updates.push((id, Some(new)));
                }
                StageRamp::Remove => {
                    let Some(o) = old else {
                        return Err(bad(
                            key(i, &format!("{at}.set")),
                            id.0.clone(),
                            "removes a load that no earlier stage applied",
                        ));
                    };
                    push(o, Ramp::Down);
                    updates.push((id, None));
                }
            }
        }
        for (id, e) in &force.edges {
            if !named_edges.contains(id) {
                loading.edge_loads.push(EdgeLoad {
                    set: id.0.clone(),
                    kind: e.kind(),
                    ramp: Ramp::Constant,
                });
            }
        }
        for (id, e) in updates {
            match e {
                Some(e) => force.edges.insert(id, e),
                None => force.edges.remove(&id),
            };
        }
        // Gravity: held, changed or removed like an edge load; one force per material.
        let map = element_materials.map(|m| m.as_slice());
        let (fixed, ramped, ramp, after) = match (&stage.gravity, force.gravity.take()) {
            (None, old) => (old.clone(), None, Ramp::Constant, old),
            (Some(g), old) => match g.ramp {
                StageRamp::Constant => {
                    let new = self.body_forces(i, g, map)?;
                    (Some(new.clone()), None, Ramp::Constant, Some(new))
                }
                StageRamp::Linear => {
                    let new = self.body_forces(i, g, map)?;
                    let zero = vec![[0.0; 2]; new.len()];
                    let change = new
                        .iter()
                        .zip(old.as_ref().unwrap_or(&zero))
                        .map(|(n, o)| [n[0] - o[0], n[1] - o[1]])
                        .collect();
                    (old, Some(change), Ramp::Linear, Some(new))
                }
                StageRamp::Remove => {
                    let Some(o) = old else {
                        return Err(bad(
                            key(i, ".gravity.ramp"),
                            "remove",
                            "removes a gravity that no earlier stage applied",
                        ));
                    };
                    (None, Some(o), Ramp::Down, None)
                }
            },
        };
        force.gravity = after;
        // A stage has one body force with one ramp: held (constant), applied (linear) or
        // removed (down).
        let map = element_materials.cloned();
        match (fixed, ramped) {
            (None, None) => {}
            (Some(f), None) => {
                loading.body = Some(body_load(f, map));
                loading.body_ramp = Ramp::Constant;
            }
            (None, Some(r)) => {
                loading.body = Some(body_load(r, map));
                loading.body_ramp = ramp;
            }
            (Some(f), Some(_)) => {
                // Held f plus r growing would need two body forces with two ramps.
                let held = if f.len() == 1 { format!("{:?}", f[0]) } else { format!("{f:?}") };
                return Err(bad(
                    key(i, ".gravity.ramp"),
                    "linear",
                    format!(
                        "changes a gravity already in force ({held}) linearly to another: remove it in one stage and apply the new one in the next, or apply it at once (ramp = \"constant\")"
                    ),
                ));
            }
        }
        Ok(self.mesh.symmetry.reduce_loading(loading, self.field()))
    }

    /// Checks that every set the stages name is in `mesh` and not empty (node sets for
    /// prescribed dofs, edge sets for pressures and tractions), naming the key.
    pub(crate) fn check_stage_sets(&self, mesh: &Mesh) -> Result<()> {
        for (i, s) in self.stage.iter().enumerate() {
            self.check_sets_of_stage(i, s, mesh)?;
        }
        Ok(())
    }

    /// [`Job::check_stage_sets`] of stage `i`, `s`.
    fn check_sets_of_stage(&self, i: usize, s: &StageSection, mesh: &Mesh) -> Result<()> {
        let unknown = |field: &'static str, set: &str, kind: &str, known: Vec<&String>| {
            let known: Vec<&str> = known.into_iter().map(String::as_str).collect();
            bad(
                field,
                set,
                format!(
                    "the mesh has no non-empty {kind} set of that name (known: {})",
                    known.join(", ")
                ),
            )
        };
        for (j, p) in s.prescribed.iter().enumerate() {
            if mesh.node_sets.get(&p.set).is_none_or(Vec::is_empty) {
                let at = key(i, &format!(".prescribed[{j}].set"));
                return Err(unknown(at, &p.set, "node", mesh.node_sets.keys().collect()));
            }
        }
        let edges = s
            .pressure
            .iter()
            .enumerate()
            .map(|(j, p)| (format!(".pressure[{j}].set"), &p.set))
            .chain(
                s.traction.iter().enumerate().map(|(j, t)| (format!(".traction[{j}].set"), &t.set)),
            );
        for (at, set) in edges {
            if mesh.edge_sets.get(set).is_none_or(Vec::is_empty) {
                return Err(unknown(key(i, &at), set, "edge", mesh.edge_sets.keys().collect()));
            }
        }
        Ok(())
    }

    /// Checks `[[stage]]`: steps, repeat, one of value / increment / path / free per
    /// prescribed entry, finite numbers, a density for gravity, and no `[loading]` loads
    /// beside stages.
    pub(crate) fn validate_stages(&self) -> Result<()> {
        if !self.is_staged() {
            return Ok(());
        }
        self.validate_staged_job()?;
        for (i, s) in self.stage.iter().enumerate() {
            self.validate_stage(i, s)?;
        }
        Ok(())
    }

    /// What a job in stages may not have: `[loading]` loads, an accuracy target.
    fn validate_staged_job(&self) -> Result<()> {
        let l = &self.loading;
        if l.compression.is_some()
            || !l.prescribed.is_empty()
            || !l.pressure.is_empty()
            || l.increment.is_some()
        {
            return Err(bad(
                "loading",
                "[loading] with loads",
                "a job in [[stage]] puts its loads in its stages; [loading] keeps only load_set",
            ));
        }
        if let Some(a) = self.accuracy {
            // The planner's load-step knob scales `[loading]`'s steps: it does not know
            // stages yet.
            return Err(bad(
                "accuracy",
                format!("{a:?}"),
                "an accuracy target plans a one-stage job; a job in [[stage]] gives each stage's steps",
            ));
        }
        Ok(())
    }

    /// [`Job::validate_stages`] of stage `i`, `s`.
    fn validate_stage(&self, i: usize, s: &StageSection) -> Result<()> {
        if s.steps == 0 || s.steps > cosdem_fem::solve::MAX_LOAD_STEPS {
            return Err(bad(
                key(i, ".steps"),
                s.steps.to_string(),
                format!("must be 1 to {}", cosdem_fem::solve::MAX_LOAD_STEPS),
            ));
        }
        if s.repeat == 0 || s.repeat > MAX_STAGES {
            return Err(bad(
                key(i, ".repeat"),
                s.repeat.to_string(),
                format!("must be 1 to {MAX_STAGES}"),
            ));
        }
        let mut paths = None;
        for (j, p) in s.prescribed.iter().enumerate() {
            let at = |k: &str| key(i, &format!(".prescribed[{j}]{k}"));
            let given = [p.value.is_some(), p.increment.is_some(), !p.path.is_empty(), p.free];
            if given.iter().filter(|g| **g).count() != 1 {
                return Err(bad(
                    at(""),
                    format!("set = {:?}", p.set),
                    "give exactly one of value, increment, path or free = true",
                ));
            }
            for v in p.value.iter().chain(&p.increment).chain(&p.path) {
                if !v.is_finite() {
                    return Err(bad(at(""), format!("{v:?}"), "must be finite"));
                }
            }
            if !p.path.is_empty() {
                match paths {
                    Some(n) if n != p.path.len() => {
                        return Err(bad(
                            at(".path"),
                            format!("{} points", p.path.len()),
                            format!("the stage's other path has {n}: paths of a stage go together"),
                        ));
                    }
                    _ => paths = Some(p.path.len()),
                }
            }
        }
        for (j, p) in s.pressure.iter().enumerate() {
            if !p.value.is_finite() {
                return Err(bad(
                    key(i, &format!(".pressure[{j}].value")),
                    format!("{:?}", p.value),
                    "must be finite",
                ));
            }
        }
        for (j, t) in s.traction.iter().enumerate() {
            if !t.value.iter().all(|v| v.is_finite()) {
                return Err(bad(
                    key(i, &format!(".traction[{j}].value")),
                    format!("{:?}", t.value),
                    "must be finite",
                ));
            }
        }
        if let Some(g) = &s.gravity {
            if !g.acceleration.iter().all(|v| v.is_finite()) {
                return Err(bad(
                    key(i, ".gravity.acceleration"),
                    format!("{:?}", g.acceleration),
                    "must be finite",
                ));
            }
            match g.density {
                Some(rho) if !(rho.is_finite() && rho > 0.0) => {
                    return Err(bad(
                        key(i, ".gravity.density"),
                        format!("{rho:?}"),
                        "a body force needs the material's bulk density (kg/m^3, finite and > 0)",
                    ));
                }
                None if g.ramp != StageRamp::Remove && !self.weighs_without_stage_density() => {
                    return Err(bad(
                        key(i, ".gravity.density"),
                        "missing",
                        "a body force needs the material's bulk density (kg/m^3, finite and > 0); it may be left out only when every material is DEM (weighed from its assembly) or its [[region]] gives a bulk_density, or with ramp = \"remove\"",
                    ));
                }
                _ => {}
            }
        }
        Ok(())
    }
}
