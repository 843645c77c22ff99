//! Range checks and combinations serde cannot express. Every error names the dotted key of
//! the job file and the value ([`Error::InvalidSetting`]); numbers are printed with `{:?}`, so
//! that `1e308` reads `1e308` and not as 309 digits.

use crate::schema::{ElementChoice, Job, MaterialSection, MeshKind, Moving};
use cosdem_dem::spec::TangentFrame;
use cosdem_fem::assembly::Kinematics;
use cosdem_fem::error::{Error, Result};
use cosdem_fem::mesh::MAX_ELEMENTS;
use cosdem_fem::solve::{MAX_LOAD_STEPS, MIN_INCREMENT_FRACTION};
use cosdem_fem::symmetry::Symmetry;
use std::collections::BTreeMap;
use std::sync::{LazyLock, Mutex};

/// Largest strain perturbation of the perturbation tangent (`tangent.strain`), checked by the
/// assembly's own validation: a central difference needs a small step, and a step near 1
/// makes the perturbed `det(F)` zero or negative.
pub use cosdem_dem::spec::MAX_TANGENT_STRAIN;

fn bad(field: &'static str, value: impl Into<String>, reason: &str) -> Error {
    Error::InvalidSetting { field, value: value.into(), reason: reason.into() }
}

/// A number as the messages print it: `{:?}` (`1e308`, `1e-300`, `0.7`, `NaN`).
fn num(v: f64) -> String {
    format!("{v:?}")
}

fn positive(field: &'static str, v: f64) -> Result<f64> {
    if v.is_finite() && v > 0.0 { Ok(v) } else { Err(bad(field, num(v), "must be finite and > 0")) }
}

/// The job-file key of a field of a material's assembly: `prefix` (`material.` or
/// `region[2].material.`) then `assembly.` and the field (`packing.side` ->
/// `material.assembly.packing.side`). The DEM spec names its fields relative to the assembly
/// with `&'static str`; the dotted keys are interned once each (the spec has a few dozen).
fn assembly_key(prefix: &str, field: &str) -> &'static str {
    interned(format!("{prefix}assembly.{field}"))
}

/// A dotted job-file key made at run time (`stage[2].pressure[0].value`, a field of
/// `[material.assembly]`) as the `&'static str` errors carry: each distinct key is leaked once
/// (a job names a few dozen).
pub(crate) fn interned(key: String) -> &'static str {
    static KEYS: LazyLock<Mutex<BTreeMap<String, &'static str>>> = LazyLock::new(Mutex::default);
    let mut keys = KEYS.lock().unwrap_or_else(|e| e.into_inner());
    keys.entry(key.clone()).or_insert_with(|| Box::leak(key.into_boxed_str()))
}

/// A value formatted by `Display` made readable: every number in it written out in more
/// digits than `{:?}` needs (`1e308` displays as 309 digits) is printed with `{:?}`; the rest
/// of the text is kept (`1e300 > r_max = 0.006`).
fn readable(value: &str) -> String {
    let numeric = |c: char| c.is_ascii_digit() || matches!(c, '.' | '-' | '+' | 'e' | 'E');
    let mut out = String::with_capacity(value.len());
    let mut rest = value;
    while let Some(start) = rest.find(|c: char| c.is_ascii_digit() || c == '-') {
        out.push_str(&rest[..start]);
        let len = rest[start..].find(|c: char| !numeric(c)).unwrap_or(rest.len() - start);
        let token = &rest[start..start + len];
        match token.parse::<f64>() {
            Ok(v) if num(v).len() < token.len() => out.push_str(&num(v)),
            _ => out.push_str(token),
        }
        rest = &rest[start + len..];
    }
    out.push_str(rest);
    out
}

/// The DEM spec's error as the job file's: the key with the material's prefix
/// (`material.assembly.`, `region[0].material.assembly.`).
fn assembly_error(prefix: &str, e: cosdem_dem::Error) -> Error {
    match e {
        cosdem_dem::Error::InvalidSpec { field, value, reason } => Error::InvalidSetting {
            field: assembly_key(prefix, field),
            value: readable(&value),
            reason: reason.into(),
        },
        other => {
            bad(interned(format!("{prefix}assembly")), other.to_string(), "invalid assembly spec")
        }
    }
}

impl Job {
    /// `[material.assembly] frame` is set by `[mesh] kinematics` (`current` under the
    /// updated-Lagrangian option); `current` with small strain is refused: its tangent is
    /// convected, which the small-strain assembly does not expect.
    fn validate_frame(&self) -> Result<()> {
        if self.mesh.kinematics == Kinematics::UpdatedLagrangian {
            return Ok(());
        }
        for (i, m) in self.materials().into_iter().enumerate() {
            if let MaterialSection::Dem { assembly } = m
                && assembly.frame == TangentFrame::Current
            {
                let prefix = if i == 0 { String::new() } else { format!("region[{}].", i - 1) };
                return Err(bad(
                    interned(format!("{prefix}material.assembly.frame")),
                    "current",
                    "needs [mesh] kinematics = \"updated_lagrangian\" (which sets it)",
                ));
            }
        }
        Ok(())
    }

    /// Checks every value that serde cannot: ranges and combinations.
    pub fn validate(&self) -> Result<()> {
        self.validate_mesh()?;
        self.validate_loading()?;
        self.validate_stages()?;
        self.validate_regions()?;
        check_material(&self.material, "material.")?;
        for (i, r) in self.region.iter().enumerate() {
            let prefix = format!("region[{i}].material.");
            check_material(&r.material, &prefix)?;
        }
        self.validate_specimens()?;
        self.validate_frame()?;
        let n = &self.newton;
        if n.max_iterations == 0 {
            return Err(bad("newton.max_iterations", "0", "must be >= 1"));
        }
        for (name, v) in [
            ("newton.force_tolerance", n.force_tolerance),
            ("newton.displacement_tolerance", n.displacement_tolerance),
            ("newton.tolerated_residual", n.tolerated_residual),
            ("newton.forced_residual", n.forced_residual),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(bad(name, num(v), "must be finite and >= 0"));
            }
        }
        if !(n.min_increment_fraction >= MIN_INCREMENT_FRACTION && n.min_increment_fraction <= 1.0)
        {
            return Err(bad(
                "newton.min_increment_fraction",
                num(n.min_increment_fraction),
                "must be in [1e-12, 1]",
            ));
        }
        if let Some(a) = self.accuracy {
            if !(a > 0.0 && a < 1.0) {
                return Err(bad(
                    "accuracy",
                    num(a),
                    "must be a fraction in (0, 1), e.g. 0.05 for 5 %",
                ));
            }
            if matches!(self.material, MaterialSection::Elastic { .. }) {
                return Err(bad(
                    "accuracy",
                    num(a),
                    "needs [material] kind = \"dem\": the measured trade is of DEM settings",
                ));
            }
        }
        positive("output.linear_range", self.output.linear_range)?;
        for &d in &self.output.field_plots_at {
            if !(d.is_finite() && d >= 0.0) {
                return Err(bad("output.field_plots_at", num(d), "must be finite and >= 0 (m)"));
            }
        }
        if let Some(curve) = &self.output.curve {
            curve.validate(self.mesh.continuum)?;
        }
        Ok(())
    }

    fn validate_mesh(&self) -> Result<()> {
        let m = &self.mesh;
        match m.kind {
            MeshKind::Rectangle => {
                let lx = m.lx.ok_or_else(|| bad("mesh.lx", "missing", "required"))?;
                let ly = m.ly.ok_or_else(|| bad("mesh.ly", "missing", "required"))?;
                positive("mesh.lx", lx)?;
                positive("mesh.ly", ly)?;
                for (name, n) in [("mesh.nx", m.nx), ("mesh.ny", m.ny)] {
                    match n {
                        Some(n) if (1..=MAX_ELEMENTS).contains(&n) => {}
                        Some(n) => {
                            return Err(bad(name, n.to_string(), "must be in [1, 1 000 000]"));
                        }
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
                if m.element == ElementChoice::T6 && nx.saturating_mul(ny) > MAX_ELEMENTS / 2 {
                    return Err(bad(
                        "mesh.nx",
                        format!("{nx} (with mesh.ny = {ny} and mesh.element = \"t6\")"),
                        "2 * nx * ny triangles must be at most MAX_ELEMENTS = 1 000 000 elements",
                    ));
                }
                for v in m.origin {
                    if !v.is_finite() {
                        return Err(bad("mesh.origin", num(v), "must be finite"));
                    }
                }
                rectangle_in_range(m.origin, [lx, ly], [nx, ny])?;
                if m.file.is_some() {
                    return Err(bad("mesh.file", "given", "only for kind = \"gmsh\""));
                }
                let even = |name: &'static str, n: Option<usize>| match n {
                    Some(n) if n % 2 == 1 => Err(bad(
                        name,
                        n.to_string(),
                        "must be even to cut the mesh on its mid-line",
                    )),
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
        Ok(())
    }

    fn validate_loading(&self) -> Result<()> {
        let l = &self.loading;
        if l.steps == 0 || l.steps > MAX_LOAD_STEPS {
            return Err(bad("loading.steps", l.steps.to_string(), "must be in [1, 1 000 000]"));
        }
        if let Some(c) = &l.compression {
            positive("loading.compression.displacement", c.displacement)?;
            // The platens would meet (or cross): every element inverts before the end.
            if let (MeshKind::Rectangle, Some(ly)) = (self.mesh.kind, self.mesh.ly)
                && c.displacement >= ly
            {
                return Err(bad(
                    "loading.compression.displacement",
                    num(c.displacement),
                    &format!("must be less than the panel's height mesh.ly = {}", num(ly)),
                ));
            }
        }
        if let Some(inc) = l.increment {
            positive("loading.increment", inc)?;
            let Some(c) = &l.compression else {
                return Err(bad("loading.increment", num(inc), "needs [loading.compression]"));
            };
            if l.control.is_some() {
                return Err(bad(
                    "loading.increment",
                    num(inc),
                    "a path-controlled run ([loading.control]) divides the control's value \
                     into `steps`: give `steps`, not a displacement increment",
                ));
            }
            if c.displacement / inc > MAX_LOAD_STEPS as f64 {
                return Err(bad(
                    "loading.increment",
                    num(inc),
                    &format!(
                        "too small: {:e} load steps for loading.compression.displacement = {}, \
                         more than 1 000 000",
                        c.displacement / inc,
                        num(c.displacement)
                    ),
                ));
            }
        }
        for p in &l.prescribed {
            if !p.value.is_finite() {
                return Err(bad("loading.prescribed.value", num(p.value), "must be finite"));
            }
        }
        for p in &l.pressure {
            if !p.value.is_finite() {
                return Err(bad("loading.pressure.value", num(p.value), "must be finite"));
            }
        }
        Ok(())
    }
}

/// The checks of one material, `[material]` or a region's, whose keys start with `prefix`
/// (`material.`, `region[2].material.`).
fn check_material(material: &MaterialSection, prefix: &str) -> Result<()> {
    let at = |name: &str| interned(format!("{prefix}{name}"));
    match material {
        MaterialSection::Elastic { shear_modulus, poisson, cosserat_modulus, length } => {
            positive(at("shear_modulus"), *shear_modulus)?;
            if !(*poisson > -1.0 && *poisson < 0.5) {
                return Err(bad(at("poisson"), num(*poisson), "must be in (-1, 0.5)"));
            }
            if let Some(gc) = cosserat_modulus
                && !(gc.is_finite() && *gc >= 0.0)
            {
                return Err(bad(at("cosserat_modulus"), num(*gc), "must be finite and >= 0"));
            }
            if let Some(lc) = length
                && !(lc.is_finite() && *lc >= 0.0)
            {
                return Err(bad(at("length"), num(*lc), "must be finite and >= 0"));
            }
            // Each value may be finite and the moduli they make still overflow.
            let m = material.elastic().expect("elastic material");
            let d = m.tangent();
            if !d[..4].iter().flatten().all(|v| v.is_finite()) {
                return Err(bad(
                    at("shear_modulus"),
                    num(*shear_modulus),
                    "with this Poisson's ratio and Cosserat modulus the elastic moduli overflow",
                ));
            }
            if !d[4][4].is_finite() {
                return Err(bad(
                    at("length"),
                    num(m.length),
                    "the bending modulus 2 G lc^2 overflows",
                ));
            }
        }
        MaterialSection::Dem { assembly } => {
            assembly.validate().map_err(|e| assembly_error(prefix, e))?;
        }
    }
    Ok(())
}

/// The rectangle's node coordinates are computed as `origin + l * i / (2 n)` (`i` up to
/// `2 n`) and the element areas from products of coordinates: both must stay finite, and an
/// element's area must not underflow (its Jacobian would be 0).
fn rectangle_in_range(origin: [f64; 2], l: [f64; 2], n: [usize; 2]) -> Result<()> {
    let reach = |k: usize| origin[k].abs() + l[k] * (2 * n[k]) as f64;
    if !(4.0 * reach(0) * reach(1)).is_finite() {
        let reason = "too large: the nodes' coordinates or their products overflow";
        let span = |k: usize| l[k] * (2 * n[k]) as f64;
        if origin[0].abs().max(origin[1].abs()) > span(0).max(span(1)) {
            let value = format!("[{}, {}]", num(origin[0]), num(origin[1]));
            return Err(bad("mesh.origin", value, reason));
        }
        let (key, v) = if span(0) >= span(1) { ("mesh.lx", l[0]) } else { ("mesh.ly", l[1]) };
        return Err(bad(key, num(v), reason));
    }
    let area = (l[0] / n[0] as f64) * (l[1] / n[1] as f64);
    if area < 1e-200 {
        let (key, v) = if l[0] <= l[1] { ("mesh.lx", l[0]) } else { ("mesh.ly", l[1]) };
        return Err(bad(
            key,
            num(v),
            &format!(
                "too small: an element's area (lx / nx) (ly / ny) = {area:e} m^2 is below 1e-200"
            ),
        ));
    }
    Ok(())
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

    /// Every message prints its numbers readably: no run of more than 17 digits (`1e308` used to
    /// print as 309 digits, `1e-300` as 300 zeros).
    fn readable(err: &str) -> bool {
        let mut run = 0;
        for c in err.chars() {
            run = if c.is_ascii_digit() { run + 1 } else { 0 };
            if run > 17 {
                return false;
            }
        }
        true
    }

    /// The cases and the other extremes: each error names its dotted key and prints
    /// the value as `{:?}` does (`1e308`, `1e-300`, `10.0`).
    #[test]
    fn errors_name_the_dotted_key_and_print_numbers_readably() {
        let panel = minimal();
        let dem = fixtures::text("dem-one-element");
        let tangent = |t: &str| {
            dem.replace("side = 0.1 }", &format!("side = 0.1 }}\ntangent = {{ kind = {t} }}"))
        };
        let cases = [
            (panel.replace("lx = 1.0", "lx = 1e308"), "mesh.lx", "1e308"),
            (panel.replace("ly = 1.0", "ly = 1e307"), "mesh.ly", "1e307"),
            (panel.replace("ly = 1.0", "ly = 1.0\norigin = [1e308, 0]"), "mesh.origin", "1e308"),
            (panel.replace("lx = 1.0", "lx = 1e-300"), "mesh.lx", "1e-300"),
            (panel.replace("steps = 4", "increment = 1e-300"), "loading.increment", "1e-300"),
            (
                panel.replace("displacement = 0.01", "displacement = 1e308"),
                "loading.compression.displacement",
                "1e308",
            ),
            (panel.replace("poisson = 0.3", "poisson = 1e308"), "material.poisson", "1e308"),
            (
                panel.replace("shear_modulus = 1e7", "shear_modulus = 1e308"),
                "material.shear_modulus",
                "1e308",
            ),
            (format!("accuracy = 1e308\n{dem}"), "accuracy", "1e308"),
            (
                format!("{panel}\n[newton]\nmin_increment_fraction = 1e-300\n"),
                "newton.min_increment_fraction",
                "1e-300",
            ),
            (
                format!("{panel}\n[output]\nfield_plots_at = [-1e308]\n"),
                "output.field_plots_at",
                "-1e308",
            ),
            (tangent("\"perturbation\", strain = 10"), "material.assembly.tangent.strain", "10.0"),
            (
                tangent("\"adaptive\", sliding = 0.5, strain = 1e308"),
                "material.assembly.tangent.strain",
                "1e308",
            ),
            (
                tangent("\"perturbation\", strain = -1e308"),
                "material.assembly.tangent.strain",
                "-1e308",
            ),
            (dem.replace("radius = 0.005", "radius = 1e-300"), "material.assembly.packing", "0.1"),
            (
                dem.replace(
                    "{ kind = \"hexagonal\", radius = 0.005, side = 0.1 }",
                    "{ kind = \"random\", r_min = 1e300, r_max = 0.006, side = 0.1, seed = 1, \
                     confining_stress = 1e5 }",
                ),
                "material.assembly.packing.r_min",
                "1e300 > r_max = 0.006",
            ),
            (
                dem.replace("[material.assembly]", "[material.assembly]\ndensity = -1e308"),
                "material.assembly.density",
                "-1e308",
            ),
            // The current frame belongs to the updated-Lagrangian option, which sets it.
            (
                dem.replace("[material.assembly]", "[material.assembly]\nframe = \"current\""),
                "material.assembly.frame",
                "current",
            ),
        ];
        for (text, key, value) in cases {
            let err = Job::from_toml(&text, "j").unwrap_err().to_string();
            assert!(err.contains(key), "{key}: {err}");
            assert!(err.contains(value), "{key}: no {value} in {err}");
            assert!(readable(&err), "{key}: {err}");
        }
        // The DEM's own messages, relative to the assembly, get the job file's prefix.
        let err = Job::from_toml(&tangent("\"perturbation\", strain = 0.0"), "j").unwrap_err();
        assert!(
            matches!(&err, cosdem_fem::Error::InvalidSetting { field, value, .. }
                if *field == "material.assembly.tangent.strain" && value == "0.0"),
            "{err}"
        );
        // A usual strain still passes.
        Job::from_toml(&tangent("\"perturbation\", strain = 1e-5"), "j").unwrap();
    }

    /// Numbers written out in full by the DEM's messages are shortened, the rest is kept.
    #[test]
    fn long_numbers_are_shortened_and_the_rest_kept() {
        let long = format!("{} > r_max = 0.006 (about 3e9 discs)", 1e300);
        assert_eq!(super::readable(&long), "1e300 > r_max = 0.006 (about 3e9 discs)");
        assert_eq!(super::readable("0.1"), "0.1");
        assert_eq!(super::readable("12 radii"), "12 radii");
        assert_eq!(super::readable(&(-1e-300f64).to_string()), "-1e-300");
        assert_eq!(super::readable("k_n = 6.7e7, x-y"), "k_n = 6.7e7, x-y");
    }
}
