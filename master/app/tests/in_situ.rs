//! The in-situ mean stress of the Gauss points ([`in_situ_mean_stress`]) on a soil column
//! under its own weight: a 1 m wide, 3 m high rectangle of 2 x 6 eight-node elements, base
//! fixed, sides on rollers (u_x = 0), top free, bulk density 2000 kg/m^3 under g = 9.81
//! m/s^2. The laterally confined column has the closed form `s_yy = -gamma (H - y)`,
//! `s_xx = K0 s_yy` with `K0 = nu / (1 - nu)` (no lateral strain), so
//! `p = gamma (H - y) (1 + K0) / 2`. The displacement `u_y` is quadratic in `y` and `u_x = 0`
//! (and `w = 0` on a Cosserat mesh), which the quadratic elements hold exactly, so the finite
//! element answer is the closed form up to round-off.

use cosdem_app::run::in_situ::in_situ_mean_stress;
use cosdem_app::run::{RunError, gauss_point_ids};
use cosdem_fem::assembly::GaussData;
use cosdem_fem::solve::{Solver, SolverSettings};
use cosdem_job::Job;

const DENSITY: f64 = 2000.0;
const G: f64 = 9.81;
const H: f64 = 3.0;

/// The column job: `continuum` is `cosserat` or `cauchy`; its `[material]` (G = 3 MPa,
/// nu = 0.45) is not the one the in-situ solve uses.
fn column(continuum: &str) -> String {
    format!(
        r#"
[mesh]
kind = "rectangle"
lx = 1.0
ly = {H}
nx = 2
ny = 6
continuum = "{continuum}"

[[stage]]
name = "geostatic"
steps = 4
prescribed = [
  {{ set = "bottom", component = "ux", value = 0.0 }},
  {{ set = "bottom", component = "uy", value = 0.0 }},
  {{ set = "left", component = "ux", value = 0.0 }},
  {{ set = "right", component = "ux", value = 0.0 }},
]
gravity = {{ acceleration = [0.0, -{G}], density = {DENSITY}, ramp = "linear" }}

[[stage]]
name = "surcharge"
steps = 2
pressure = [{{ set = "top", value = 5.0e4, ramp = "linear" }}]

[material]
kind = "elastic"
shear_modulus = 3e6
poisson = 0.45
"#
    )
}

fn job(continuum: &str) -> Job {
    Job::from_toml(&column(continuum), "in-situ column").unwrap()
}

/// The `y` of every Gauss point of the job's mesh, element-major.
fn gauss_y(job: &Job) -> Vec<f64> {
    let model = job.model().unwrap();
    GaussData::new(&model.mesh, model.rule).unwrap().x.iter().map(|x| x[1]).collect()
}

/// The closed form `p = gamma (H - y) (1 + K0) / 2`.
fn column_p(y: f64, nu: f64) -> f64 {
    let k0 = nu / (1.0 - nu);
    DENSITY * G * (H - y) * (1.0 + k0) / 2.0
}

/// Largest error of `p` against the closed form, relative to the closed form at the same
/// point (every Gauss point is inside the column, so that is > 0: at least 3.5 % of the base
/// stress, the top row's points lying 0.106 m below the top).
fn worst_error(job: &Job, p: &[f64], nu: f64) -> f64 {
    gauss_y(job)
        .iter()
        .zip(p)
        .map(|(&y, &p)| (p - column_p(y, nu)).abs() / column_p(y, nu))
        .fold(0.0, f64::max)
}

/// Relative tolerance of every point: the elements hold the exact solution, so only the
/// linear solve's round-off separates the answer from the closed form (about the condition
/// number of this system of 106 or 159 dofs, ~1e4, times 1e-16 of the base stress, i.e. ~1e-12 and
/// ~3e-11 of the smallest p; measured: at most 1.5e-11 of the point's p). The force
/// tolerance does not enter: the one step's predictor is the exact solve. 1e-8 is far above
/// the round-off and far below any modelling error (a lost gravity term, K0 = 1 or the
/// surcharge of the second stage move p by 10 % or more).
const TOL: f64 = 1e-8;

/// Every Gauss point of the Cauchy and of the Cosserat column gets the closed-form `p` of the
/// geostatic stage alone (the second stage's surcharge of 50 kPa, 30 % of the base stress,
/// is not in it), one per Gauss point in the order of `gauss_point_ids`.
#[test]
fn a_column_under_gravity_gets_its_k0_mean_stress() {
    let nu = 0.25;
    for continuum in ["cauchy", "cosserat"] {
        let job = job(continuum);
        let p = in_situ_mean_stress(&job, nu).unwrap();
        let solver = Solver::new(job.model().unwrap(), SolverSettings::default()).unwrap();
        assert_eq!(p.len(), gauss_point_ids(&solver).len(), "{continuum}");
        assert_eq!(p.len(), 12 * 4, "{continuum}");
        let err = worst_error(&job, &p, nu);
        println!("{continuum}: worst relative error of p {err:.2e}");
        assert!(err < TOL, "{continuum}: {err:e}");
    }
}

/// `nu` changes `p` as `(1 + K0) / 2` says: from nu = 0.25 (K0 = 1/3) to nu = 0.4 (K0 = 2/3)
/// every point's `p` grows by the factor 5/4, and nu = 0 (K0 = 0) gives half the vertical
/// stress. The job's own `poisson = 0.45` would give yet another factor. Tolerance: as above,
/// the two answers are each within [`TOL`] of their closed forms.
#[test]
fn the_poisson_ratio_scales_p_as_k0_predicts() {
    let job = job("cosserat");
    let p25 = in_situ_mean_stress(&job, 0.25).unwrap();
    for nu in [0.4, 0.0] {
        let p = in_situ_mean_stress(&job, nu).unwrap();
        let err = worst_error(&job, &p, nu);
        println!("nu = {nu}: worst relative error of p {err:.2e}");
        assert!(err < TOL, "nu = {nu}: {err:e}");
        let factor = (1.0 + nu / (1.0 - nu)) / (1.0 + 0.25 / 0.75);
        for (a, b) in p.iter().zip(&p25) {
            assert!((a - factor * b).abs() <= 2.0 * TOL * a, "{a} vs {factor} * {b}");
        }
    }
}

/// The job's `[material]` and Newton tolerances are not the in-situ solve's: the same column
/// as a DEM job with the loose tolerances of the DEM fixtures (5e-3) gets the same `p` (the
/// one linear step's predictor is the exact solve whatever the tolerance), without any worker.
#[test]
fn a_dem_job_with_loose_tolerances_gets_the_same_answer() {
    let elastic = job("cosserat");
    let text = column("cosserat").replace(
        "[material]\nkind = \"elastic\"\nshear_modulus = 3e6\npoisson = 0.45\n",
        "[newton]\nforce_tolerance = 5.0e-3\ndisplacement_tolerance = 5.0e-3\n\n\
         [material]\nkind = \"dem\"\n\n[material.assembly]\n\
         packing = { kind = \"hexagonal\", radius = 0.005, side = 0.1 }\n",
    );
    assert!(text.contains("kind = \"dem\""));
    let dem = Job::from_toml(&text, "in-situ column, dem").unwrap();
    let (a, b) =
        (in_situ_mean_stress(&elastic, 0.3).unwrap(), in_situ_mean_stress(&dem, 0.3).unwrap());
    for (x, y) in a.iter().zip(&b) {
        assert!((x - y).abs() <= TOL * x, "{x} vs {y}");
    }
    assert!(worst_error(&dem, &b, 0.3) < TOL);
}

/// A Poisson ratio outside (-1, 0.5) (incompressible, beyond it, or not a number) is refused
/// naming `specimens.poisson` and the value, before anything is solved.
#[test]
fn a_poisson_ratio_outside_its_range_is_refused_naming_the_key() {
    let job = job("cauchy");
    for nu in [0.5, 0.7, -1.0, -3.0, f64::NAN, f64::INFINITY] {
        let e = in_situ_mean_stress(&job, nu).unwrap_err();
        assert!(
            matches!(
                &e,
                RunError::Solver(cosdem_fem::Error::InvalidSetting {
                    field: "specimens.poisson",
                    ..
                })
            ),
            "{nu}: {e}"
        );
        let text = e.to_string();
        assert!(text.contains("specimens.poisson") && text.contains(&format!("{nu:?}")), "{text}");
    }
    // The edges' neighbours inside the range are accepted.
    for nu in [0.499, -0.99] {
        assert!(in_situ_mean_stress(&job, nu).is_ok(), "{nu}");
    }
}
