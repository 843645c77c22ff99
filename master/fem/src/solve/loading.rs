//! Boundary conditions and loads, all scaled by the load factor `lambda` in [0, 1] of a
//! stage: a prescribed dof goes from its value at the start of the stage to its target, a
//! load follows its [`Ramp`]. A one-stage run starts from zero.

use crate::assembly::{Component, DofMap, Field, GaussData};
use crate::element::{edge_shape, gauss_1d};
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use std::fmt;
use std::sync::Arc;

/// A prescribed dof value on a named node set, reached at `lambda = 1` (linear growth from
/// its value at the start of the stage).
#[derive(Clone, Debug, PartialEq)]
pub struct Dirichlet {
    /// Node set name.
    pub set: String,
    /// Which component.
    pub component: Component,
    /// Value at the end of the stage (m or rad); with `relative`, the change over the stage.
    pub value: f64,
    /// `value` is an increment on each dof's value at the start of the stage (an unloading
    /// is a negative one; 0 holds the dof where it is), not a target.
    pub relative: bool,
}

impl Dirichlet {
    /// `component = value` on `set` at the end of the stage.
    pub fn new(set: &str, component: Component, value: f64) -> Self {
        Self { set: set.to_string(), component, value, relative: false }
    }

    /// `component` of `set` moved by `value` over the stage from where it is.
    pub fn increment(set: &str, component: Component, value: f64) -> Self {
        Self { set: set.to_string(), component, value, relative: true }
    }
}

/// Path control of a stage ([`super::control`]): its steps advance the mean of `component`
/// over the node set `set` by `value` in all (from its value at the start of the stage), and
/// the load factor of every prescribed dof and load is solved for at each step; it may fall
/// (a snap-back) or exceed 1. The stage ends when the control quantity reaches its end.
#[derive(Clone, Debug, PartialEq)]
pub struct PathControl {
    /// Node set name.
    pub set: String,
    /// Which component.
    pub component: Component,
    /// The control quantity's change over the stage (m or rad).
    pub value: f64,
    /// Further terms of the control quantity: it is the mean of `component` over `set` plus
    /// each term's weighted mean (a combination such as a platen's displacement plus a
    /// multiple of a side's bulge).
    pub plus: Vec<ControlTerm>,
}

/// A term of a [`PathControl`]'s quantity: `weight` times the mean of `component` over `set`.
#[derive(Clone, Debug, PartialEq)]
pub struct ControlTerm {
    /// Node set name.
    pub set: String,
    /// Which component.
    pub component: Component,
    /// Its weight (finite).
    pub weight: f64,
}

/// How a load follows the load factor of its stage.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Ramp {
    /// Grows with `lambda` (zero at the start, full at the end).
    #[default]
    Linear,
    /// Full from the first step on (e.g. a confining pressure held while the platens move).
    Constant,
    /// Full at the start, removed linearly to zero at the end (an unloading).
    Down,
}

/// What acts on an edge set.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EdgeLoadKind {
    /// Pressure `p` (Pa, positive pushes into the body): traction `-p n`.
    Pressure(f64),
    /// Traction vector `[t_x, t_y]` (Pa).
    Traction([f64; 2]),
}

/// A distributed load on a named boundary edge set.
#[derive(Clone, Debug, PartialEq)]
pub struct EdgeLoad {
    /// Edge set name.
    pub set: String,
    /// Pressure or traction.
    pub kind: EdgeLoadKind,
    /// How it follows the load factor.
    pub ramp: Ramp,
}

/// Body force and body couple density `[F_x, F_y, M]` (N/m^3, N m/m^3) as a function
/// `f(element, [x, y])` of the element and the position of a Gauss point, following
/// [`Loading::body_ramp`] (`M` is ignored by the Cauchy field).
///
/// `element` is the 0-based index of the element the Gauss point lies in, as in
/// [`Mesh::element_nodes`] and [`Mesh::element_sets`] (so each region of the mesh can have
/// its own density); `[x, y]` is the Gauss point's position (m).
#[derive(Clone)]
pub struct BodyLoad(pub Arc<dyn Fn(usize, [f64; 2]) -> [f64; 3] + Send + Sync>);

impl fmt::Debug for BodyLoad {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("BodyLoad(<fn>)")
    }
}

impl BodyLoad {
    /// Wraps a density function `f(element, [x, y])`.
    pub fn new(f: impl Fn(usize, [f64; 2]) -> [f64; 3] + Send + Sync + 'static) -> Self {
        Self(Arc::new(f))
    }
}

/// Every boundary condition and load of a run.
#[derive(Clone, Debug, Default)]
pub struct Loading {
    /// Prescribed dofs; where two entries hit the same dof the later wins.
    pub dirichlet: Vec<Dirichlet>,
    /// Edge loads.
    pub edge_loads: Vec<EdgeLoad>,
    /// Body force and couple.
    pub body: Option<BodyLoad>,
    /// How the body force follows the load factor (default linear).
    pub body_ramp: Ramp,
    /// Prescribed values of single dofs `(node, component, value at lambda = 1)`, applied
    /// after the set-based ones (for manufactured solutions and analytical profiles).
    pub nodal_dirichlet: Vec<(usize, Component, f64)>,
    /// Path control: the steps advance this quantity, the load factor follows (`None`: the
    /// steps advance the load factor).
    pub control: Option<PathControl>,
}

/// The loading turned into global vectors for one mesh and dof map.
#[derive(Clone, Debug, PartialEq)]
pub struct LoadVectors {
    /// Prescribed flag per dof.
    pub prescribed: Vec<bool>,
    /// Prescribed value per dof at `lambda = 1` (0 on free dofs).
    pub prescribed_value: Vec<f64>,
    /// External force of the ramped loads at `lambda = 1`.
    pub f_linear: Vec<f64>,
    /// External force of the constant loads.
    pub f_constant: Vec<f64>,
    /// Every dof's value at the start of the stage, from which the prescribed ones move to
    /// their targets; `None` in the first stage (they start from zero).
    pub prescribed_start: Option<Vec<f64>>,
}

impl LoadVectors {
    /// External force at load factor `lambda` (> 0).
    pub fn f_ext(&self, lambda: f64) -> Vec<f64> {
        self.f_linear.iter().zip(&self.f_constant).map(|(a, b)| lambda * a + b).collect()
    }

    /// Value of prescribed dof `k` at load factor `lambda`: from its start value to its
    /// target (`lambda * target` in the first stage, as before stages existed).
    pub fn prescribed_at(&self, k: usize, lambda: f64) -> f64 {
        let v = self.prescribed_value[k];
        match &self.prescribed_start {
            None => lambda * v,
            Some(start) => start[k] + lambda * (v - start[k]),
        }
    }
}

/// Where a load of the given ramp goes: `(into f_constant, into f_linear)` factors.
fn ramp_factors(ramp: Ramp) -> (f64, f64) {
    match ramp {
        Ramp::Linear => (0.0, 1.0),
        Ramp::Constant => (1.0, 0.0),
        Ramp::Down => (1.0, -1.0),
    }
}

/// Platen friction in the compression scenes (THEORY.md section 4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Platens {
    /// `u_x = 0` on top and bottom (the default).
    Rough,
    /// `u_x` free on top and bottom, except at the `bottom_left` node (no rigid translation).
    Smooth,
}

impl Loading {
    /// Compression between platens: `u_y = bottom_uy` on `bottom`, `u_y = top_uy` on `top`
    /// at the end of the loading (e.g. `top_uy = -d`, `bottom_uy = 0`), `w` free. With
    /// [`Platens::Smooth`] the mesh needs a `bottom_left` node set (structured meshes have one).
    pub fn compression(top_uy: f64, bottom_uy: f64, platens: Platens) -> Self {
        let mut dirichlet = vec![
            Dirichlet::new("bottom", Component::Uy, bottom_uy),
            Dirichlet::new("top", Component::Uy, top_uy),
        ];
        match platens {
            Platens::Rough => {
                dirichlet.push(Dirichlet::new("bottom", Component::Ux, 0.0));
                dirichlet.push(Dirichlet::new("top", Component::Ux, 0.0));
            }
            Platens::Smooth => dirichlet.push(Dirichlet::new("bottom_left", Component::Ux, 0.0)),
        }
        Self { dirichlet, ..Default::default() }
    }

    /// Which dofs are prescribed and to what, before the dof map exists (a first stage:
    /// relative values count from zero).
    pub fn prescribed(&self, mesh: &Mesh, field: Field) -> Result<(Vec<bool>, Vec<f64>)> {
        self.prescribed_from(mesh, field, None)
    }

    /// Which dofs are prescribed and to what target, a relative value counting from `start`
    /// (every dof's value at the start of the stage; zero when `None`).
    pub fn prescribed_from(
        &self,
        mesh: &Mesh,
        field: Field,
        start: Option<&[f64]>,
    ) -> Result<(Vec<bool>, Vec<f64>)> {
        let ndf = field.ndf();
        let mut flag = vec![false; mesh.n_nodes() * ndf];
        let mut value = vec![0.0; mesh.n_nodes() * ndf];
        for d in &self.dirichlet {
            if field == Field::Cauchy && d.component == Component::W {
                return Err(Error::InvalidSetting {
                    field: "dirichlet.component",
                    value: format!("W on `{}`", d.set),
                    reason: "the Cauchy field has no micro-rotation".into(),
                });
            }
            if !d.value.is_finite() {
                return Err(Error::InvalidSetting {
                    field: "dirichlet.value",
                    value: d.value.to_string(),
                    reason: "must be finite".into(),
                });
            }
            for &n in mesh.node_set(&d.set)? {
                let k = n * ndf + d.component.offset();
                flag[k] = true;
                value[k] = match (d.relative, start) {
                    (true, Some(u)) => u[k] + d.value,
                    _ => d.value,
                };
            }
        }
        for &(n, c, v) in &self.nodal_dirichlet {
            if n >= mesh.n_nodes()
                || (field == Field::Cauchy && c == Component::W)
                || !v.is_finite()
            {
                return Err(Error::InvalidSetting {
                    field: "nodal_dirichlet",
                    value: format!("({n}, {c:?}, {v})"),
                    reason: "node out of range, W on a Cauchy field, or non-finite value".into(),
                });
            }
            let k = n * ndf + c.offset();
            flag[k] = true;
            value[k] = v;
        }
        Ok((flag, value))
    }

    /// The loading without its pressures: the dead part under the updated-Lagrangian option,
    /// whose pressures follow the deformed edges (`solve/follower.rs`).
    pub fn without_pressures(&self) -> Self {
        let mut dead = self.clone();
        dead.edge_loads.retain(|l| !matches!(l.kind, EdgeLoadKind::Pressure(_)));
        dead
    }

    /// Integrates edge and body loads (a first stage).
    pub fn vectors(&self, mesh: &Mesh, dofs: &DofMap, gauss: &GaussData) -> Result<LoadVectors> {
        self.vectors_from(mesh, dofs, gauss, None)
    }

    /// Integrates edge and body loads of a stage that starts from the dof values `start`
    /// (see [`LoadVectors::prescribed_start`]).
    pub fn vectors_from(
        &self,
        mesh: &Mesh,
        dofs: &DofMap,
        gauss: &GaussData,
        start: Option<&[f64]>,
    ) -> Result<LoadVectors> {
        let (prescribed, prescribed_value) = self.prescribed_from(mesh, dofs.field, start)?;
        let ndf = dofs.field.ndf();
        let mut f_linear = vec![0.0; dofs.n_dofs()];
        let mut f_constant = vec![0.0; dofs.n_dofs()];
        let (t1, w1) = gauss_1d(3);
        for load in &self.edge_loads {
            let (fc, fl) = ramp_factors(load.ramp);
            for edge in mesh.edge_set(&load.set)? {
                let x: Vec<[f64; 2]> = edge.nodes.iter().map(|&n| mesh.nodes[n]).collect();
                for (t, w) in t1.iter().zip(&w1) {
                    let (n, dn) = edge_shape(*t);
                    let dx = [0, 1].map(|i| (0..3).map(|a| dn[a] * x[a][i]).sum::<f64>());
                    // outward normal times length element: tangent turned clockwise
                    let nds = [dx[1], -dx[0]];
                    let len = (dx[0] * dx[0] + dx[1] * dx[1]).sqrt();
                    let tr = match load.kind {
                        EdgeLoadKind::Pressure(p) => [-p * nds[0], -p * nds[1]],
                        EdgeLoadKind::Traction(tv) => [tv[0] * len, tv[1] * len],
                    };
                    for a in 0..3 {
                        for i in 0..2 {
                            let f = n[a] * tr[i] * w;
                            let k = edge.nodes[a] * ndf + i;
                            // Exactly as before stages for the two old ramps (no 0 * f terms:
                            // they would turn a -0 into +0).
                            if fl != 0.0 {
                                f_linear[k] += fl * f;
                            }
                            if fc != 0.0 {
                                f_constant[k] += fc * f;
                            }
                        }
                    }
                }
            }
        }
        if let Some(body) = &self.body {
            let (fc, fl) = ramp_factors(self.body_ramp);
            for g in 0..gauss.len() {
                let element = gauss.element_of(g);
                let f = (body.0)(element, gauss.x[g]);
                let el = mesh.element_nodes(element);
                for (a, &node) in el.iter().enumerate() {
                    let s = gauss.shape(g)[a] * gauss.weight[g];
                    for c in 0..ndf {
                        let k = node * ndf + c;
                        if fl != 0.0 {
                            f_linear[k] += fl * (s * f[c]);
                        }
                        if fc != 0.0 {
                            f_constant[k] += fc * (s * f[c]);
                        }
                    }
                }
            }
        }
        Ok(LoadVectors {
            prescribed,
            prescribed_value,
            f_linear,
            f_constant,
            prescribed_start: start.map(<[f64]>::to_vec),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::element::{ElementKind, QuadratureRule};

    /// A pressure p on each side of a 2 x 1.5 rectangle adds up to p times the side length,
    /// pointing into the body; a traction likewise (exact: quadratic shape functions on
    /// straight edges, 3-point rule), for the quadrilaterals and the triangles alike (an
    /// edge is the same 3-node line).
    #[test]
    fn edge_loads_add_up_to_their_resultants() {
        for kind in [ElementKind::Q8, ElementKind::Q9, ElementKind::T6] {
            let mesh = Mesh::rectangle(kind, 2.0, 1.5, 3, 2, [0.0, 0.0]).unwrap();
            let dofs =
                DofMap::new(Field::Cosserat, mesh.n_nodes(), &vec![false; 3 * mesh.n_nodes()]);
            let gauss = GaussData::new(&mesh, QuadratureRule::for_kind(kind, false)).unwrap();
            for (side, expect) in [
                ("right", [-3.0, 0.0]),
                ("left", [3.0, 0.0]),
                ("top", [0.0, -4.0]),
                ("bottom", [0.0, 4.0]),
            ] {
                let loading = Loading {
                    edge_loads: vec![EdgeLoad {
                        set: side.into(),
                        kind: EdgeLoadKind::Pressure(2.0),
                        ramp: Ramp::Linear,
                    }],
                    ..Default::default()
                };
                let v = loading.vectors(&mesh, &dofs, &gauss).unwrap();
                let sum = [0, 1].map(|c| v.f_ext(1.0).iter().skip(c).step_by(3).sum::<f64>());
                assert!(
                    (sum[0] - expect[0]).abs() < 1e-13 && (sum[1] - expect[1]).abs() < 1e-13,
                    "{side}: {sum:?}"
                );
            }
        }
    }
}
