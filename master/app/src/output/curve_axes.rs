//! The load-displacement curve of any boundary-value job (`[output.curve]`): its abscissa is
//! the mean displacement of a control node set in one direction, its ordinate one reaction
//! component of a node set, and further sets' reactions become extra `curve.csv` columns.
//!
//! Pure functions of the step report and the converged solution; the run writer
//! ([`super::run_dir::RunWriter`]) puts them in rows.

use cosdem_fem::assembly::Component;
use cosdem_fem::solve::{SolutionView, StepReport};

/// One quantity of a node set, times a factor.
#[derive(Clone, Debug, PartialEq)]
pub struct SetQuantity {
    /// Node set name.
    pub set: String,
    /// Dof component (for a reaction: `Ux` gives R_x, `Uy` R_y, `W` the moment R_w).
    pub component: Component,
    /// Factor applied (e.g. -1 so that a settlement is positive).
    pub scale: f64,
}

impl SetQuantity {
    /// The short name of the component: `ux`, `uy` or `w`.
    fn component_name(&self) -> &'static str {
        match self.component {
            Component::Ux => "ux",
            Component::Uy => "uy",
            Component::W => "w",
        }
    }

    /// `-1 × ` before a quantity with a scale other than 1, nothing otherwise.
    fn scale_prefix(&self) -> String {
        if self.scale == 1.0 {
            String::new()
        } else {
            format!("{} × ", super::fmt_f64(self.scale))
        }
    }
}

/// What the curve is made of.
#[derive(Clone, Debug, PartialEq)]
pub struct CurveAxes {
    /// The abscissa: mean over the set's nodes of the converged dof, times the scale.
    pub control: SetQuantity,
    /// The ordinate: the set's reaction component, times the scale.
    pub load: SetQuantity,
    /// Sets whose reactions R_x and R_y are extra columns `R_x:SET`, `R_y:SET`.
    pub reactions: Vec<String>,
}

impl CurveAxes {
    /// The mean over the nodes of the control set of the converged dof, times the control
    /// scale; `None` when the set is unknown or empty, or the component is not a dof of the
    /// view's field (the job's validation refuses those before the run).
    pub fn control_displacement(&self, view: &SolutionView<'_>) -> Option<f64> {
        let nodes = view.mesh.node_sets.get(&self.control.set)?;
        let ndf = view.field.ndf();
        let k = self.control.component.offset();
        if nodes.is_empty() || k >= ndf {
            return None;
        }
        let sum: f64 = nodes.iter().map(|&n| view.dofs[n * ndf + k]).sum();
        // `+ 0.0` turns a held set's -0 (0 times a negative scale) into 0 and changes no
        // other value.
        Some(self.control.scale * sum / nodes.len() as f64 + 0.0)
    }

    /// The load: the load set's reaction component times the load scale (0 for a set the
    /// report lacks; the job's validation refuses unknown sets).
    pub fn load(&self, report: &StepReport) -> f64 {
        let k = self.load.component.offset();
        self.load.scale * report.reactions.get(&self.load.set).map_or(0.0, |r| r[k])
    }

    /// The names of the extra reaction columns, `R_x:SET`, `R_y:SET` per set in order.
    pub fn reaction_columns(&self) -> Vec<String> {
        self.reactions.iter().flat_map(|s| [format!("R_x:{s}"), format!("R_y:{s}")]).collect()
    }

    /// The values of [`Self::reaction_columns`] at a step (N per metre of thickness).
    pub fn reaction_values(&self, report: &StepReport) -> Vec<f64> {
        self.reactions
            .iter()
            .flat_map(|s| report.reactions.get(s).map_or([0.0, 0.0], |r| [r[0], r[1]]))
            .collect()
    }

    /// Axis labels of the load-displacement figure: `[abscissa, ordinate]`, e.g.
    /// `"-1 × uy of footing (m)"` and `"R_y of footing (N/m)"`.
    pub fn labels(&self) -> [String; 2] {
        let c = &self.control;
        let unit = if c.component == Component::W { "rad" } else { "m" };
        let abscissa = format!("{}{} of {} ({unit})", c.scale_prefix(), c.component_name(), c.set);
        let l = &self.load;
        let (name, unit) = match l.component {
            Component::Ux => ("R_x", "N/m"),
            Component::Uy => ("R_y", "N/m"),
            Component::W => ("R_w", "N m/m"),
        };
        let ordinate = format!("{}{name} of {} ({unit})", l.scale_prefix(), l.set);
        [abscissa, ordinate]
    }
}

impl From<&cosdem_job::CurveQuantity> for SetQuantity {
    fn from(q: &cosdem_job::CurveQuantity) -> Self {
        Self { set: q.set.clone(), component: q.component(), scale: q.scale }
    }
}

impl From<&cosdem_job::CurveSection> for CurveAxes {
    fn from(c: &cosdem_job::CurveSection) -> Self {
        Self {
            control: (&c.control).into(),
            load: (&c.load).into(),
            reactions: c.reactions.clone(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cosdem_fem::assembly::Field;
    use cosdem_fem::mesh::Mesh;
    use std::collections::BTreeMap;

    fn axes() -> CurveAxes {
        CurveAxes {
            control: SetQuantity { set: "top".into(), component: Component::Uy, scale: -1.0 },
            load: SetQuantity { set: "top".into(), component: Component::Uy, scale: 2.0 },
            reactions: vec!["left".into(), "top".into()],
        }
    }

    /// The control displacement is the mean of the set's dofs times the scale: on a 1 x 1
    /// mesh of one Q8 element with the top nodes at u_y = -1, -2, -3 (mean -2) and scale -1,
    /// it is exactly 2; the load and the reaction columns read the report's reactions.
    #[test]
    fn control_load_and_reaction_columns() {
        let mesh =
            Mesh::rectangle(cosdem_fem::element::ElementKind::Q8, 1.0, 1.0, 1, 1, [0.0, 0.0])
                .unwrap();
        let top = mesh.node_sets["top"].clone();
        assert_eq!(top.len(), 3);
        let mut dofs = vec![0.0; 3 * mesh.n_nodes()];
        for (i, &n) in top.iter().enumerate() {
            dofs[3 * n + 1] = -(i as f64 + 1.0);
            dofs[3 * n] = 7.0;
        }
        let view =
            SolutionView { mesh: &mesh, field: Field::Cosserat, dofs: &dofs, gauss_points: &[] };
        let a = axes();
        assert_eq!(a.control_displacement(&view), Some(2.0));
        let mut reactions = BTreeMap::new();
        reactions.insert("top".to_string(), [1.0, -3.0, 0.5]);
        reactions.insert("left".to_string(), [4.0, 5.0, 0.0]);
        let report = StepReport {
            step: 1,
            stage: 0,
            load_factor: 0.5,
            time: 0.5,
            increment: 0.5,
            iterations: 1,
            residuals: vec![],
            line_search_halvings: 0,
            cuts: 0,
            tolerated: false,
            forced: false,
            reactions,
            dem_steps: 0,
        };
        assert_eq!(a.load(&report), -6.0);
        assert_eq!(a.reaction_columns(), ["R_x:left", "R_y:left", "R_x:top", "R_y:top"]);
        assert_eq!(a.reaction_values(&report), [4.0, 5.0, 1.0, -3.0]);
        let [x, y] = a.labels();
        assert_eq!(x, "-1 × uy of top (m)");
        assert_eq!(y, "2 × R_y of top (N/m)");
        let mut unknown = a.clone();
        unknown.control.set = "nosuch".into();
        assert_eq!(unknown.control_displacement(&view), None);
        // A held set (a footing before it is pushed) under scale -1 reads 0, not "-0".
        let held = vec![0.0; 3 * mesh.n_nodes()];
        let view = SolutionView { dofs: &held, ..view };
        let zero = a.control_displacement(&view).unwrap();
        assert!(zero == 0.0 && zero.is_sign_positive(), "{zero}");
    }
}
