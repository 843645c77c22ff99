//! `[output.curve]`: which quantities make the run's load-displacement curve.
//!
//! Without the table the curve is the paper's platen compression (abscissa
//! `load_factor * loading.compression.displacement`, ordinate `-R_y` of `loading.load_set`).
//! With it, any boundary-value job gets a curve: the abscissa is the mean displacement of a
//! control node set in one direction, the ordinate one reaction component of a node set, and
//! `reactions` adds both reaction components of further sets as columns of `curve.csv`.

use crate::schema::{ComponentChoice, Continuum, Job};
use cosdem_fem::assembly::Component;
use cosdem_fem::error::{Error, Result};
use cosdem_fem::mesh::Mesh;
use serde::{Deserialize, Serialize};

/// `[output.curve]`: the curve's axes and the extra reaction columns.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CurveSection {
    /// The abscissa: the mean over the set's nodes of one converged nodal dof, times `scale`.
    pub control: CurveQuantity,
    /// The ordinate: one reaction component of a node set, times `scale`.
    pub load: CurveQuantity,
    /// Node sets whose reactions `R_x`, `R_y` are written as extra `curve.csv` columns
    /// (`R_x:SET`, `R_y:SET`, in this order).
    #[serde(default)]
    pub reactions: Vec<String>,
}

/// One quantity of a node set: `{ set = "footing", component = "uy", scale = -1 }`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CurveQuantity {
    /// Node set (`top`, `bottom`, `left`, `right`, corners, or a Gmsh physical name).
    pub set: String,
    /// `ux`, `uy` or `w` (`w`: Cosserat only; the reaction of `w` is a moment).
    pub component: ComponentChoice,
    /// Factor applied to the quantity (default 1; e.g. -1 so that a settlement is positive).
    #[serde(default = "one")]
    pub scale: f64,
}

fn one() -> f64 {
    1.0
}

/// What the `.pvd` series' `timestep` attribute holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PvdTime {
    /// The curve's abscissa (the compression's displacement, or the control displacement).
    Displacement,
    /// Stages finished plus the stage's load factor (the load factor in a one-stage job).
    PseudoTime,
}

impl CurveQuantity {
    /// The solver's component.
    pub fn component(&self) -> Component {
        self.component.into()
    }
}

fn bad(field: &'static str, value: impl Into<String>, reason: impl Into<String>) -> Error {
    Error::InvalidSetting { field, value: value.into(), reason: reason.into() }
}

impl CurveSection {
    /// Ranges and combinations: finite non-zero scales, `w` only on a Cosserat continuum,
    /// no set named twice in `reactions`.
    pub fn validate(&self, continuum: Continuum) -> Result<()> {
        for (q, scale_key, comp_key) in [
            (&self.control, "output.curve.control.scale", "output.curve.control.component"),
            (&self.load, "output.curve.load.scale", "output.curve.load.component"),
        ] {
            if !(q.scale.is_finite() && q.scale != 0.0) {
                return Err(bad(
                    scale_key,
                    format!("{:?}", q.scale),
                    "must be finite and non-zero",
                ));
            }
            if q.component == ComponentChoice::W && continuum == Continuum::Cauchy {
                return Err(bad(comp_key, "w", "needs mesh.continuum = \"cosserat\""));
            }
        }
        for (i, s) in self.reactions.iter().enumerate() {
            if self.reactions[..i].contains(s) {
                return Err(bad("output.curve.reactions", s.clone(), "is named twice"));
            }
        }
        Ok(())
    }

    /// Checks that every set named exists in `mesh`: an unknown name would give a curve of
    /// zeros. The error names the key and the value, and lists the known sets.
    pub fn check_sets(&self, mesh: &Mesh) -> Result<()> {
        let known = || mesh.node_sets.keys().cloned().collect::<Vec<_>>().join(", ");
        let named = [
            ("output.curve.control.set", &self.control.set),
            ("output.curve.load.set", &self.load.set),
        ]
        .into_iter()
        .chain(self.reactions.iter().map(|s| ("output.curve.reactions", s)));
        for (key, set) in named {
            if !mesh.node_sets.contains_key(set) {
                return Err(bad(
                    key,
                    set.clone(),
                    format!("the mesh has no node set of that name (known: {})", known()),
                ));
            }
        }
        Ok(())
    }
}

impl Job {
    /// What the `.pvd` timesteps are, decided from the job before the run: the displacement
    /// for a compression job without `[output.curve]` (as before the table existed) and for a
    /// job whose control quantity is prescribed (`[[loading.prescribed]]` or a compression
    /// platen on that set and component, the last such entry) with `value * scale > 0`, in a
    /// single stage: the control displacement then grows with the load factor. Otherwise
    /// (no control, a control that is not prescribed, or one that decreases) the pseudo-time.
    pub fn pvd_time(&self) -> PvdTime {
        let Some(curve) = &self.output.curve else {
            return if self.loading.compression.is_some() {
                PvdTime::Displacement
            } else {
                PvdTime::PseudoTime
            };
        };
        let control = &curve.control;
        let component = control.component();
        let prescribed = self
            .loading()
            .dirichlet
            .iter()
            .rev()
            .find(|d| d.set == control.set && d.component == component)
            .map(|d| d.value);
        match prescribed {
            Some(v) if v * control.scale > 0.0 => PvdTime::Displacement,
            _ => PvdTime::PseudoTime,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures;

    fn with_curve(extra: &str) -> std::result::Result<Job, String> {
        let base = fixtures::text("elastic-panel");
        let job = Job::from_toml(&format!("{base}\n{extra}"), "test").map_err(|e| e.to_string())?;
        job.model().map_err(|e| e.to_string())?;
        Ok(job)
    }

    /// The table reads with its defaults (scale 1, no extra reactions).
    #[test]
    fn a_curve_table_reads_with_defaults() {
        let job = with_curve(
            "[output.curve]\ncontrol = { set = \"top\", component = \"uy\", scale = -1 }\n\
             load = { set = \"top\", component = \"uy\" }\n",
        )
        .unwrap();
        let c = job.output.curve.unwrap();
        assert_eq!(c.control.scale, -1.0);
        assert_eq!(c.load.scale, 1.0);
        assert_eq!(c.load.component, ComponentChoice::Uy);
        assert!(c.reactions.is_empty());
    }

    /// Every set named must exist: the error names the key and the value, before any run.
    #[test]
    fn unknown_sets_are_refused_naming_key_and_value() {
        let cases = [
            (
                "control = { set = \"nosuch\", component = \"uy\" }\nload = { set = \"top\", component = \"uy\" }",
                "output.curve.control.set",
            ),
            (
                "control = { set = \"top\", component = \"uy\" }\nload = { set = \"nosuch\", component = \"uy\" }",
                "output.curve.load.set",
            ),
            (
                "control = { set = \"top\", component = \"uy\" }\nload = { set = \"top\", component = \"uy\" }\nreactions = [\"bottom\", \"nosuch\"]",
                "output.curve.reactions",
            ),
        ];
        for (table, key) in cases {
            let err = with_curve(&format!("[output.curve]\n{table}\n")).unwrap_err();
            assert!(err.contains(key) && err.contains("nosuch"), "{table}: {err}");
        }
    }

    /// Scales must be finite and non-zero; a set named twice in `reactions` is refused.
    #[test]
    fn bad_scales_and_repeated_reactions_are_refused() {
        let base = "control = { set = \"top\", component = \"uy\" }\n";
        let err = with_curve(&format!(
            "[output.curve]\n{base}load = {{ set = \"top\", component = \"uy\", scale = 0 }}\n"
        ))
        .unwrap_err();
        assert!(err.contains("output.curve.load.scale"), "{err}");
        let err = with_curve(&format!(
            "[output.curve]\n{base}load = {{ set = \"top\", component = \"uy\" }}\n\
             reactions = [\"left\", \"left\"]\n"
        ))
        .unwrap_err();
        assert!(err.contains("output.curve.reactions") && err.contains("left"), "{err}");
    }

    /// The `.pvd` time rule: a prescribed control growing with `scale` is the displacement;
    /// the same control scaled the other way, or a set that is not prescribed, the
    /// pseudo-time; no table: displacement for a compression job, else pseudo-time.
    #[test]
    fn pvd_time_is_decided_from_the_job() {
        let panel = fixtures::load("elastic-panel");
        assert!(panel.loading.compression.is_some());
        assert_eq!(panel.pvd_time(), PvdTime::Displacement);
        let mut job = panel.clone();
        job.loading.compression = None;
        job.loading.prescribed = vec![crate::Prescribed {
            set: "top".into(),
            component: ComponentChoice::Uy,
            value: -1e-3,
        }];
        assert_eq!(job.pvd_time(), PvdTime::PseudoTime);
        let q = |set: &str, scale: f64| CurveQuantity {
            set: set.into(),
            component: ComponentChoice::Uy,
            scale,
        };
        job.output.curve =
            Some(CurveSection { control: q("top", -1.0), load: q("top", 1.0), reactions: vec![] });
        assert_eq!(job.pvd_time(), PvdTime::Displacement);
        job.output.curve.as_mut().unwrap().control.scale = 1.0;
        assert_eq!(job.pvd_time(), PvdTime::PseudoTime);
        job.output.curve.as_mut().unwrap().control = q("left", -1.0);
        assert_eq!(job.pvd_time(), PvdTime::PseudoTime);
    }
}
