//! Range checks and combinations serde cannot express. Every error names the key and the value
//! ([`Error::InvalidSetting`]).

use crate::schema::{Job, MaterialSection, MeshKind, Moving};
use cosdem_fem::error::{Error, Result};
use cosdem_fem::mesh::MAX_ELEMENTS;
use cosdem_fem::solve::{MAX_LOAD_STEPS, MIN_INCREMENT_FRACTION};
use cosdem_fem::symmetry::Symmetry;

fn bad(field: &'static str, value: impl ToString, reason: &str) -> Error {
    Error::InvalidSetting { field, value: value.to_string(), reason: reason.into() }
}

fn positive(field: &'static str, v: f64) -> Result<f64> {
    if v.is_finite() && v > 0.0 { Ok(v) } else { Err(bad(field, v, "must be finite and > 0")) }
}

impl Job {
    /// Checks every value that serde cannot: ranges and combinations.
    pub fn validate(&self) -> Result<()> {
        let m = &self.mesh;
        match m.kind {
            MeshKind::Rectangle => {
                positive("mesh.lx", m.lx.ok_or_else(|| bad("mesh.lx", "missing", "required"))?)?;
                positive("mesh.ly", m.ly.ok_or_else(|| bad("mesh.ly", "missing", "required"))?)?;
                for (name, n) in [("mesh.nx", m.nx), ("mesh.ny", m.ny)] {
                    match n {
                        Some(n) if (1..=MAX_ELEMENTS).contains(&n) => {}
                        Some(n) => return Err(bad(name, n, "must be in [1, 1 000 000]")),
                        None => return Err(bad(name, "missing", "required for a rectangle")),
                    }
                }
                let (nx, ny) = (m.nx.unwrap_or(1), m.ny.unwrap_or(1));
                if nx.saturating_mul(ny) > MAX_ELEMENTS {
                    return Err(bad(
                        "mesh.nx",
                        format!("{nx} (with mesh.ny = {ny})"),
                        "nx * ny must be at most MAX_ELEMENTS = 1 000 000 elements",
                    ));
                }
                for v in m.origin {
                    if !v.is_finite() {
                        return Err(bad("mesh.origin", v, "must be finite"));
                    }
                }
                if m.file.is_some() {
                    return Err(bad("mesh.file", "given", "only for kind = \"gmsh\""));
                }
                let even = |name: &'static str, n: Option<usize>| match n {
                    Some(n) if n % 2 == 1 => {
                        Err(bad(name, n, "must be even to cut the mesh on its mid-line"))
                    }
                    _ => Ok(()),
                };
                if m.symmetry != Symmetry::None {
                    even("mesh.nx", m.nx)?;
                }
                if m.symmetry == Symmetry::Quarter {
                    even("mesh.ny", m.ny)?;
                    let both = self.loading.compression.as_ref().map(|c| c.moving);
                    if both != Some(Moving::Both) {
                        return Err(bad(
                            "mesh.symmetry",
                            "quarter",
                            "needs [loading.compression] with moving = \"both\" (symmetric about the horizontal mid-line)",
                        ));
                    }
                }
            }
            MeshKind::Gmsh => {
                if m.symmetry != Symmetry::None {
                    return Err(bad("mesh.symmetry", "given", "only for kind = \"rectangle\""));
                }
                if m.file.is_none() {
                    return Err(bad("mesh.file", "missing", "required for kind = \"gmsh\""));
                }
            }
        }
        let l = &self.loading;
        if l.steps == 0 || l.steps > MAX_LOAD_STEPS {
            return Err(bad("loading.steps", l.steps, "must be in [1, 1 000 000]"));
        }
        if let Some(c) = &l.compression {
            positive("loading.compression.displacement", c.displacement)?;
        }
        if let Some(inc) = l.increment {
            positive("loading.increment", inc)?;
            let Some(c) = &l.compression else {
                return Err(bad("loading.increment", inc, "needs [loading.compression]"));
            };
            if c.displacement / inc > MAX_LOAD_STEPS as f64 {
                return Err(bad(
                    "loading.increment",
                    inc,
                    "too small: more than 1 000 000 load steps for the compression displacement",
                ));
            }
        }
        for p in &l.prescribed {
            if !p.value.is_finite() {
                return Err(bad("loading.prescribed.value", p.value, "must be finite"));
            }
        }
        for p in &l.pressure {
            if !p.value.is_finite() {
                return Err(bad("loading.pressure.value", p.value, "must be finite"));
            }
        }
        match &self.material {
            MaterialSection::Elastic { shear_modulus, poisson, cosserat_modulus, length } => {
                positive("material.shear_modulus", *shear_modulus)?;
                if !(*poisson > -1.0 && *poisson < 0.5) {
                    return Err(bad("material.poisson", poisson, "must be in (-1, 0.5)"));
                }
                if let Some(gc) = cosserat_modulus
                    && !(gc.is_finite() && *gc >= 0.0)
                {
                    return Err(bad("material.cosserat_modulus", gc, "must be finite and >= 0"));
                }
                if let Some(lc) = length
                    && !(lc.is_finite() && *lc >= 0.0)
                {
                    return Err(bad("material.length", lc, "must be finite and >= 0"));
                }
                // Each value may be finite and the moduli they make still overflow.
                let m = self.elastic().expect("elastic material");
                let d = m.tangent();
                if !d[..4].iter().flatten().all(|v| v.is_finite()) {
                    return Err(bad(
                        "material.shear_modulus",
                        shear_modulus,
                        "with this Poisson's ratio and Cosserat modulus the elastic moduli overflow",
                    ));
                }
                if !d[4][4].is_finite() {
                    return Err(bad(
                        "material.length",
                        m.length,
                        "the bending modulus 2 G lc^2 overflows",
                    ));
                }
            }
            MaterialSection::Dem { assembly } => assembly.validate().map_err(|e| {
                Error::JobFile { file: "[material.assembly]".into(), message: e.to_string() }
            })?,
        }
        let n = &self.newton;
        if n.max_iterations == 0 {
            return Err(bad("newton.max_iterations", 0, "must be >= 1"));
        }
        for (name, v) in [
            ("newton.force_tolerance", n.force_tolerance),
            ("newton.displacement_tolerance", n.displacement_tolerance),
            ("newton.tolerated_residual", n.tolerated_residual),
            ("newton.forced_residual", n.forced_residual),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(bad(name, v, "must be finite and >= 0"));
            }
        }
        if !(n.min_increment_fraction >= MIN_INCREMENT_FRACTION && n.min_increment_fraction <= 1.0)
        {
            return Err(bad(
                "newton.min_increment_fraction",
                n.min_increment_fraction,
                "in [1e-12, 1]",
            ));
        }
        if let Some(a) = self.accuracy {
            if !(a > 0.0 && a < 1.0) {
                return Err(bad("accuracy", a, "must be a fraction in (0, 1), e.g. 0.05 for 5 %"));
            }
            if matches!(self.material, MaterialSection::Elastic { .. }) {
                return Err(bad(
                    "accuracy",
                    a,
                    "needs [material] kind = \"dem\": the measured trade is of DEM settings",
                ));
            }
        }
        positive("output.linear_range", self.output.linear_range)?;
        for &d in &self.output.field_plots_at {
            if !(d.is_finite() && d >= 0.0) {
                return Err(bad("output.field_plots_at", d, "must be finite and >= 0 (m)"));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use crate::{Job, PAPER_LINEAR_RANGE, fixtures};

    fn minimal() -> String {
        fixtures::text("elastic-panel")
    }

    #[test]
    fn out_of_range_values_name_key_and_value() {
        let text = minimal().replace("poisson = 0.3", "poisson = 0.7");
        let err = Job::from_toml(&text, "j").unwrap_err().to_string();
        assert!(err.contains("material.poisson") && err.contains("0.7"), "{err}");
        let text = minimal().replace("displacement = 0.01", "displacement = -0.01");
        let err = Job::from_toml(&text, "j").unwrap_err().to_string();
        assert!(err.contains("loading.compression.displacement") && err.contains("-0.01"), "{err}");
        let text = minimal().replace("nx = 2", "nx = 0");
        let err = Job::from_toml(&text, "j").unwrap_err().to_string();
        assert!(err.contains("mesh.nx"), "{err}");
    }

    /// `accuracy` is optional, a fraction in (0, 1), and only for DEM jobs; errors name the
    /// key and the value.
    #[test]
    fn accuracy_key_is_validated() {
        assert_eq!(Job::from_toml(&minimal(), "j").unwrap().accuracy, None);
        let dem = fixtures::text("dem-one-element");
        let with = |a: &str| format!("accuracy = {a}\n{dem}");
        assert_eq!(Job::from_toml(&with("0.05"), "j").unwrap().accuracy, Some(0.05));
        for bad in ["0.0", "1.0", "-0.1", "5", "nan"] {
            let err = Job::from_toml(&with(bad), "j").unwrap_err().to_string();
            assert!(err.contains("accuracy") && err.contains("(0, 1)"), "{bad}: {err}");
        }
        let err = Job::from_toml(&format!("accuracy = 0.05\n{}", minimal()), "j").unwrap_err();
        assert!(err.to_string().contains("accuracy") && err.to_string().contains("dem"), "{err}");
    }

    /// E's linear range is the paper's 0.01 m unless the job sets its own (the run writer reads it,
    /// `cosdem_app::run::run_settings`); a range that is not a positive length is refused naming the key.
    #[test]
    fn linear_range_defaults_to_the_papers_and_is_validated() {
        let job = Job::from_toml(&minimal(), "j").unwrap();
        assert_eq!(job.output.linear_range, PAPER_LINEAR_RANGE);
        assert_eq!(job.output.linear_range, 0.01);
        let with = |v: &str| format!("{}\n[output]\nlinear_range = {v}\n", minimal());
        let job = Job::from_toml(&with("1e-3"), "j").unwrap();
        assert_eq!(job.output.linear_range, 1e-3);
        for bad in ["0.0", "-1e-3", "nan", "inf"] {
            let err = Job::from_toml(&with(bad), "j").unwrap_err().to_string();
            assert!(err.contains("output.linear_range"), "{bad}: {err}");
        }
    }
}
