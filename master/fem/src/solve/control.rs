//! Path control (indirect displacement control, de Borst 1987): the steps of a stage advance
//! a control quantity, the mean of one displacement component over a node set, instead of the
//! load factor, which becomes an unknown of each step. A load-displacement path that turns
//! back (a snap-back: the platen would have to move back while the band slides) is then
//! followed as long as the control quantity keeps growing along it.
//!
//! With the prescribed dofs `u_c(lambda)` and the loads `f_ext(lambda)` affine in `lambda`,
//! the residual on the free dofs `r(u_f, lambda)` linearizes as
//! `K_ff du_f + q dlambda = -r` with `q = K_fc g - f_hat`, `g = d u_c / d lambda` and
//! `f_hat = d f_ext / d lambda` (the free rows). The correction is
//! `du_f = a + dlambda b`, `K_ff a = -r`, `K_ff b = -q` (one factorization, two right-hand
//! sides), and `dlambda` makes the iterate meet the linear constraint
//! `tau(u) = c . u = tau_target`:
//!
//! `dlambda = (tau_target - tau(u) - c_f . a) / (c_f . b + c_c . g)`.
//!
//! The constraint is linear, so a full update meets it to round-off; a line-search halving
//! leaves part of it for the next iteration (the correction measures `tau_target - tau(u)`).

use super::loading::{ControlTerm, LoadVectors, PathControl};
use crate::assembly::{DofMap, Field};
use crate::error::{Error, Result};
use crate::mesh::Mesh;

/// A [`PathControl`] resolved on a mesh: the control quantity's weights and its values at
/// the start and the end of the stage.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct ControlDofs {
    /// `(dof, weight)`: the mean of the component over the set's nodes.
    weights: Vec<(usize, f64)>,
    /// The control quantity at the start of the stage (m).
    start: f64,
    /// Its change over the stage (m).
    value: f64,
}

impl ControlDofs {
    /// Resolves `control` on `mesh`, counting from the dof values `start` (every dof's value
    /// at the start of the stage; zero when `None`).
    pub(super) fn new(
        control: &PathControl,
        mesh: &Mesh,
        field: Field,
        start: Option<&[f64]>,
    ) -> Result<Self> {
        if !(control.value.is_finite() && control.value != 0.0) {
            return Err(Error::InvalidSetting {
                field: "control.value",
                value: control.value.to_string(),
                reason: "must be finite and not zero (the control quantity's change over the \
                         stage)"
                    .into(),
            });
        }
        let primary =
            ControlTerm { set: control.set.clone(), component: control.component, weight: 1.0 };
        let mut weights = Vec::new();
        for (i, term) in std::iter::once(&primary).chain(&control.plus).enumerate() {
            let at = |rest: &str| -> &'static str {
                match (i, rest) {
                    (0, "set") => "control.set",
                    (0, _) => "control.component",
                    (_, "set") => "control.plus.set",
                    (_, "weight") => "control.plus.weight",
                    _ => "control.plus.component",
                }
            };
            if field == Field::Cauchy && term.component.offset() == 2 {
                return Err(Error::InvalidSetting {
                    field: at("component"),
                    value: format!("w on `{}`", term.set),
                    reason: "the Cauchy field has no micro-rotation".into(),
                });
            }
            if !term.weight.is_finite() {
                return Err(Error::InvalidSetting {
                    field: at("weight"),
                    value: term.weight.to_string(),
                    reason: "must be finite".into(),
                });
            }
            let nodes = mesh.node_set(&term.set)?;
            if nodes.is_empty() {
                return Err(Error::InvalidSetting {
                    field: at("set"),
                    value: term.set.clone(),
                    reason: "the node set is empty".into(),
                });
            }
            let w = term.weight / nodes.len() as f64;
            let ndf = field.ndf();
            weights.extend(nodes.iter().map(|&n| (n * ndf + term.component.offset(), w)));
        }
        let start = start.map_or(0.0, |u| weights.iter().map(|&(d, w)| w * u[d]).sum());
        Ok(Self { weights, start, value: control.value })
    }

    /// The control quantity at `u` (all dofs).
    pub(super) fn tau(&self, u: &[f64]) -> f64 {
        self.weights.iter().map(|&(d, w)| w * u[d]).sum()
    }

    /// The control quantity's target at progress `s` of the stage (0 at its start, 1 at its
    /// end).
    pub(super) fn target(&self, s: f64) -> f64 {
        self.start + s * self.value
    }

    /// The load-factor correction that brings the iterate `u` onto the constraint after the
    /// free-dof corrections `a` (at fixed load factor) and `b` (per unit load factor), `g` the
    /// prescribed dofs' rate (all dofs); `None` when the control does not move with the load
    /// factor (a zero denominator).
    pub(super) fn correction(
        &self,
        dofs: &DofMap,
        u: &[f64],
        a: &[f64],
        b: &[f64],
        g: &[f64],
        tau_target: f64,
    ) -> Option<f64> {
        let (mut ca, mut rate) = (0.0, 0.0);
        for &(d, w) in &self.weights {
            match dofs.equation[d] {
                usize::MAX => rate += w * g[d],
                eq => {
                    ca += w * a[eq];
                    rate += w * b[eq];
                }
            }
        }
        let dl = (tau_target - self.tau(u) - ca) / rate;
        tracing::debug!(c_a = ca, rate, "path control terms");
        (rate != 0.0 && dl.is_finite()).then_some(dl)
    }
}

impl LoadVectors {
    /// The prescribed dofs' rate `d u_c / d lambda` (all dofs; 0 on free ones).
    pub(super) fn prescribed_rate(&self) -> Vec<f64> {
        (0..self.prescribed.len())
            .map(|k| {
                if self.prescribed[k] {
                    self.prescribed_at(k, 1.0) - self.prescribed_at(k, 0.0)
                } else {
                    0.0
                }
            })
            .collect()
    }
}
