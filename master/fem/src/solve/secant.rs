//! Gauss-point secant updates of the material tangent within a load step.
//!
//! A relaxed DEM assembly answers with the paper (contact-stiffness) tangent, which counts every
//! sticking contact as elastic. Once contacts slide the relaxed response is much softer than
//! that tangent, and Newton with it contracts only by about `1 - K_true / K_paper` per
//! iteration: on the biaxial example 8-14 iterations per step before the peak and up to 21,
//! the cap, past it (docs/notes/tradeoff-biaxial-5mm.md). The relaxation answers are what they are;
//! the tangent is only the iteration matrix, so it may be improved from what the iterations
//! already measured. Measured value (docs/notes/substep-biaxial.md): before the peak 3-4 iterations
//! per step and half the DEM steps; past the peak none (the updates end at the first stall).
//! Off by default.
//!
//! Each Gauss point keeps its own matrix `B`, starting from the material's tangent at the
//! step's start, and after every evaluation scales `B`'s stiffness along the direction the
//! point just moved to what that move measured, from the last two answers of the point,
//! `de = e_k - e_{k-1}`, `ds = s_k - s_{k-1}`:
//!
//! `B <- B - (1 - s) (B de) (B^T de)^T / (de . B de)`, `s = (de . ds) / (de . B de)`,
//!
//! so that `de . B de = de . ds` (the work along the move is the measured one) and `B` is
//! unchanged on every direction conjugate to `de`. It is a rank-one secant update in the
//! family of Broyden's, chosen for noisy answers, which a relaxed assembly gives (its
//! stress scatters by about its relaxation tolerance):
//! - the stiffness along a move stays between [`MIN_RATIO`] and 1 times the step's starting
//!   tangent's: the paper tangent is the stiffest consistent slope of a frictional network
//!   (every sticking contact elastic), a relaxed answer is softer, and a ratio measured as
//!   zero or negative between two noisy answers would make the matrix singular;
//! - a move below [`MIN_RELATIVE_STEP`] of the step's own increment at the point is noise and
//!   takes no update;
//! - an iteration that does not contract the residual ends the updates for the rest of the
//!   attempt ([`RESTART_CONTRACTION`]).
//!
//! Measured first with Broyden's "good" update (`B <- B + (ds - B de) de^T / (de . de)`, the
//! full secant condition `B de = ds`): on the biaxial example the noise of the late, small
//! corrections entered the matrix whole, corrections of millimetres on a 5 cm sample
//! followed, and steps took 15-20 iterations with line searches (no faster than without).
//!
//! Why the global iteration follows: the FE matrix is `K = sum_p G_p^T B_p G_p w_p` with
//! `G_p` the strain-displacement operator. On a scene whose residual has one soft mode (the
//! lateral expansion of the biaxial test, where every point moves alike) the update makes
//! Newton the secant method on that mode instead of a fixed-point iteration with the elastic
//! slope (once the moves fall below the noise threshold it keeps the last secant: fast
//! linear convergence). It is the quasi-Newton idea of structural
//! codes (BFGS in Abaqus and Code_Aster) applied where the nonlinearity sits, at the material
//! points: no global vectors, one matrix per point.
//!
//! Deterministic: `B` depends only on the point's answers within the attempt, never on the
//! worker or thread count. It lives within one attempt at a load step (a cut or a new step
//! starts again from the material's tangent), so a checkpoint at a step boundary carries
//! nothing of it and a resumed run is bit-identical.

use cosdem_common::voigt::{KX, KY, N, XX, YY};
use cosdem_common::{StressVector, Tangent};

/// Smallest `|de|` between two answers, relative to the step's strain increment at the point,
/// that takes an update: below it the difference of two answers is dominated by relaxation
/// noise (a relaxation stops at an unbalanced-force ratio of 1e-4, and its stress scatters by
/// about that fraction of the stress), not a slope.
pub const MIN_RELATIVE_STEP: f64 = 0.05;

/// Smallest ratio of the updated stiffness along a direction to the step's starting tangent's:
/// the update softens, never to zero (a vanishing or negative slope measured between two
/// noisy answers would make the matrix singular, and past the peak of the biaxial example a
/// floor of 0.02 of the current matrix let corrections drift by tenths of a millimetre per
/// iteration until a Gauss point inverted).
pub const MIN_RATIO: f64 = 0.05;

/// The metric weights of the strain components: 1 for the four strains, `l^2` for the two
/// curvatures, `l^2 = (C_kxkx + C_kyky) / (C_xxxx + C_yyyy)` from `c` (1 when either is not
/// positive: a tangent without couple stiffness, where the curvature columns carry nothing).
pub fn metric(c: &Tangent) -> [f64; N] {
    let couple = c[KX][KX] + c[KY][KY];
    let normal = c[XX][XX] + c[YY][YY];
    let l2 = if couple > 0.0 && normal > 0.0 && (couple / normal).is_finite() {
        couple / normal
    } else {
        1.0
    };
    [1.0, 1.0, 1.0, 1.0, l2, l2]
}

/// The directional secant update of `b` from the strain change `de` and the stress change
/// `ds` between two answers (see the module doc): the stiffness along `de` is set to the
/// measured one, `B <- B - (1 - s) (B de) (B^T de)^T / (de . B de)` with
/// `s = w / (de . B de)` and the work `w = de . ds` kept between [`MIN_RATIO`] and 1 times
/// `de . C0 de` of the step's starting tangent `c0`; then `de . B de = w`, and `B` is
/// unchanged on every direction `u` with `(B^T de) . u = 0`. Bounding against `c0`, not
/// against the current `B`, keeps repeated updates along one direction from compounding.
/// `step` is the step's own strain increment at this point: a change below
/// [`MIN_RELATIVE_STEP`] of its size is relaxation noise, not a slope. Returns false (and
/// leaves `b` alone) when the step is too small, the work along it is not positive under `b`
/// or `c0`, or anything is not finite.
pub fn directional_secant(
    b: &mut Tangent,
    c0: &Tangent,
    de: &[f64; N],
    ds: &StressVector,
    step: &[f64; N],
) -> bool {
    let m = metric(c0);
    let size_of = |v: &[f64; N]| (0..N).map(|i| m[i] * v[i] * v[i]).sum::<f64>().sqrt();
    let size = size_of(de);
    if !(size.is_finite() && size > MIN_RELATIVE_STEP * size_of(step) && size > 0.0) {
        return false;
    }
    let quadratic = |c: &Tangent| -> f64 {
        (0..N).map(|i| de[i] * (0..N).map(|j| c[i][j] * de[j]).sum::<f64>()).sum()
    };
    let bde: [f64; N] = std::array::from_fn(|i| (0..N).map(|j| b[i][j] * de[j]).sum::<f64>());
    let btde: [f64; N] = std::array::from_fn(|j| (0..N).map(|i| de[i] * b[i][j]).sum::<f64>());
    let (elastic, initial) = (quadratic(b), quadratic(c0));
    let work: f64 = (0..N).map(|i| de[i] * ds[i]).sum();
    let usable = elastic > 0.0 && elastic.is_finite() && initial > 0.0 && initial.is_finite();
    if !(usable && work.is_finite()) {
        return false;
    }
    let s = work.clamp(MIN_RATIO * initial, initial) / elastic;
    let mut next = *b;
    for i in 0..N {
        for j in 0..N {
            next[i][j] -= (1.0 - s) * bde[i] * btde[j] / elastic;
        }
    }
    if !next.iter().flatten().all(|v| v.is_finite()) {
        return false;
    }
    *b = next;
    true
}

/// An iteration whose relative residual is above this fraction of the previous one did not
/// contract: the updates end for the rest of the attempt, which iterates with the answers' own
/// tangents, as without the option (so the option costs at most the iterations before the
/// stall). Past a peak a relaxed assembly's answers scatter, and a matrix softened by that
/// scatter lets corrections drift: measured on the biaxial example without this safeguard,
/// the residual rose from 0.6 % to 1.4 % over twenty iterations, and the whole example took
/// 829 s with 71 tolerated steps (another run shared the machine), against 62.5 s and 3 with
/// it on a quiet machine (the default: 67.5 s, 7). The
/// textbook restart (updates start again from the answers' tangents) was tried on the smooth
/// softening panel of `master/tests/newton.rs`: near its peak it took 222 iterations, the
/// same as this rule, against 102 without updates.
pub const RESTART_CONTRACTION: f64 = 0.9;

/// One Gauss point's secant state within an attempt: the last answer's strain and stress,
/// and the updated matrix.
#[derive(Clone, Debug, PartialEq)]
pub struct PointSecant {
    /// Strain at the step's start.
    pub start: [f64; N],
    /// Strain of the last answer.
    pub strain: [f64; N],
    /// Stress of the last answer.
    pub stress: StressVector,
    /// The updated tangent.
    pub matrix: Tangent,
    /// The tangent at the step's start (the bounds of the update).
    pub initial: Tangent,
}

impl PointSecant {
    /// Starts from an answer (`strain`, `stress`) and its tangent.
    pub fn new(strain: [f64; N], stress: StressVector, tangent: Tangent) -> Self {
        Self { start: strain, strain, stress, matrix: tangent, initial: tangent }
    }

    /// Takes the next answer of the point: updates the matrix from the change since the last
    /// one and remembers the new answer. Returns whether the matrix was updated.
    pub fn advance(&mut self, strain: [f64; N], stress: StressVector) -> bool {
        let de: [f64; N] = std::array::from_fn(|i| strain[i] - self.strain[i]);
        let ds: StressVector = std::array::from_fn(|i| stress[i] - self.stress[i]);
        let step: [f64; N] = std::array::from_fn(|i| strain[i] - self.start[i]);
        let updated = directional_secant(&mut self.matrix, &self.initial, &de, &ds, &step);
        self.strain = strain;
        self.stress = stress;
        updated
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn elastic() -> Tangent {
        let mut c = [[0.0; N]; N];
        c[XX][XX] = 6.5e7;
        c[YY][YY] = 6.5e7;
        c[XX][YY] = 9e6;
        c[YY][XX] = 9e6;
        c[2][2] = 4.6e7;
        c[3][3] = 4.6e7;
        c[2][3] = 9e6;
        c[3][2] = 9e6;
        c[KX][KX] = 27.0;
        c[KY][KY] = 27.0;
        c
    }

    /// A step's strain increment of 1e-3 (the noise threshold's scale in these tests).
    const STEP: [f64; N] = [1e-3, 0.0, 0.0, 0.0, 0.0, 0.0];

    /// `B v` for a matrix and a vector.
    fn apply(b: &Tangent, v: &[f64; N]) -> [f64; N] {
        std::array::from_fn(|i| (0..N).map(|j| b[i][j] * v[j]).sum())
    }

    fn dot(a: &[f64; N], b: &[f64; N]) -> f64 {
        (0..N).map(|i| a[i] * b[i]).sum()
    }

    #[test]
    fn the_update_meets_the_work_along_de_and_keeps_conjugate_directions() {
        let c0 = elastic();
        let mut b = c0;
        let de = [1e-4, -2e-4, 3e-5, 0.0, 1e-3, 0.0];
        // A softer answer than the tangent's along de: ratio about 0.3.
        let ds = apply(&c0, &de).map(|v| 0.3 * v + 1.0);
        assert!(directional_secant(&mut b, &c0, &de, &ds, &[1e-4, 0.0, 0.0, 0.0, 0.0, 0.0]));
        // de . B de = de . ds: to rounding of the largest term (6.5e7 * 4e-8 = 2.6, a few
        // ulps relative).
        let (work, elastic) = (dot(&de, &ds), dot(&de, &apply(&b, &de)));
        assert!((elastic - work).abs() <= 1e-12 * 2.6 * 10.0, "{elastic} vs {work}");
        // A direction u with (B^T de) . u = 0 is untouched: B u = B_0 u.
        let btde: [f64; N] = std::array::from_fn(|j| (0..N).map(|i| de[i] * c0[i][j]).sum());
        let mut u = [0.0; N];
        u[XX] = 2e-4;
        u[YY] = 1e-4;
        u[2] = -(btde[XX] * u[XX] + btde[YY] * u[YY]) / btde[2];
        let (bu, cu) = (apply(&b, &u), apply(&c0, &u));
        for i in 0..N {
            assert!((bu[i] - cu[i]).abs() <= 1e-11 * 1.3e4, "row {i}: {} vs {}", bu[i], cu[i]);
        }
    }

    #[test]
    fn the_update_only_softens_and_never_below_min_ratio() {
        let c0 = elastic();
        let de = [2e-4, -1e-4, 0.0, 0.0, 0.0, 0.0];
        let elastic0 = dot(&de, &apply(&c0, &de));
        // Stiffer than the tangent: nothing to soften, the ratio is capped at 1.
        let mut b = c0;
        assert!(directional_secant(&mut b, &c0, &de, &apply(&c0, &de).map(|v| 2.0 * v), &STEP));
        assert!((dot(&de, &apply(&b, &de)) - elastic0).abs() <= 1e-12 * elastic0);
        // Negative work (a softening answer or noise): MIN_RATIO of the stiffness stays.
        let mut b = c0;
        assert!(directional_secant(&mut b, &c0, &de, &apply(&c0, &de).map(|v| -v), &STEP));
        let kept = dot(&de, &apply(&b, &de)) / elastic0;
        assert!((kept - MIN_RATIO).abs() <= 1e-12, "{kept}");
    }

    #[test]
    fn noise_sized_or_non_finite_steps_leave_the_matrix_alone() {
        let c0 = elastic();
        let mut b = c0;
        let de = [1e-6, 0.0, 0.0, 0.0, 0.0, 0.0];
        // 1e-6 against a step increment of 1e-3: below MIN_RELATIVE_STEP, noise.
        assert!(!directional_secant(&mut b, &c0, &de, &[1.0; N], &STEP));
        assert!(!directional_secant(
            &mut b,
            &c0,
            &[f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0],
            &[1.0; N],
            &STEP
        ));
        assert!(!directional_secant(
            &mut b,
            &c0,
            &[1e-3, 0.0, 0.0, 0.0, 0.0, 0.0],
            &[f64::INFINITY; N],
            &STEP
        ));
        assert!(!directional_secant(&mut b, &c0, &[0.0; N], &[1.0; N], &[0.0; N]));
        assert_eq!(b, c0);
    }

    /// The reason for the update: a one-dof softening law `s(e) = k e / (1 + (e / e0)^2)`
    /// solved for `s = target` with the initial slope `k` (the "paper tangent") as the
    /// iteration matrix takes many fixed-point iterations near the peak, the directional secant a
    /// handful. The counts are this law's: the test checks their order with a margin.
    #[test]
    fn the_secant_iteration_converges_where_the_elastic_slope_crawls() {
        let (k, e0) = (1e8, 1e-3);
        let law = |e: f64| k * e / (1.0 + (e / e0) * (e / e0));
        let target = 0.45 * k * e0; // the peak is 0.5 k e0 at e = e0
        let solve = |update: bool| -> u32 {
            let mut p = PointSecant::new([0.0; N], [0.0; N], {
                let mut c = [[0.0; N]; N];
                for (i, row) in c.iter_mut().enumerate() {
                    row[i] = k;
                }
                c
            });
            let mut e = 0.0;
            for it in 1..=200 {
                let s = law(e);
                if (s - target).abs() <= 1e-8 * target {
                    return it;
                }
                if update {
                    let mut strain = [0.0; N];
                    strain[XX] = e;
                    let mut stress = [0.0; N];
                    stress[XX] = s;
                    p.advance(strain, stress);
                }
                e += (target - s) / p.matrix[XX][XX];
            }
            200
        };
        let (fixed, secant) = (solve(false), solve(true));
        // Measured: 45 with the elastic slope, 13 with the update (its last iterations move
        // less than MIN_RELATIVE_STEP of the step and keep the last secant: linear, fast).
        assert!(secant <= 15, "secant iterations {secant}, fixed {fixed}");
        assert!(fixed >= 3 * secant, "fixed slope {fixed} against secant {secant}");
    }
}
