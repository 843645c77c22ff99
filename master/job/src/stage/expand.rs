//! A job's stages expanded into what the solver runs ([`SolverStage`]): repetitions and path
//! points unrolled, the loads in force carried from stage to stage (held dofs, edge loads,
//! gravity), all at once ([`Job::stages`]) or one `[[stage]]` at a time
//! ([`Job::next_stages`], for a caller that gives its stages as it goes).

use super::{MAX_STAGES, SolverStage, StageRamp, StageSection, bad, component, key};
use crate::convert::require_set;
use crate::region::body_load;
use crate::schema::Job;
use cosdem_fem::assembly::Component;
use cosdem_fem::error::Result;
use cosdem_fem::mesh::Mesh;
use cosdem_fem::solve::{Dirichlet, EdgeLoad, EdgeLoadKind, Loading, Ramp};
use std::collections::BTreeMap;
use std::sync::Arc;

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
        let mut loading = Loading {
            control: stage.control.as_ref().map(crate::schema::ControlSection::path_control),
            ..Default::default()
        };
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
        for (j, p) in s.prescribed.iter().enumerate() {
            let at = key(i, &format!(".prescribed[{j}].set"));
            require_set(at, &p.set, "node", &mesh.node_sets)?;
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
            require_set(key(i, &at), set, "edge", &mesh.edge_sets)?;
        }
        if let Some(c) = &s.control {
            crate::convert::check_control(&format!("stage[{i}].control"), c, mesh)?;
        }
        Ok(())
    }
}
