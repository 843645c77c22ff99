//! Micro-structure descriptors of an assembly, as FEMxDEM studies publish them per Gauss
//! point: porosity and void ratio, coordination numbers, the contact-normal fabric and its
//! anisotropy, the sliding fraction and the mean disc rotation.
//!
//! Pure observations of a state: [`describe`] reads radii, rotations, the cell area and a
//! list of contacts; [`of_state`] takes the contacts of the homogenization
//! ([`crate::homogenize::for_each_contact`]: overlapping or touching within 1e-9 of the radii
//! sum, in pair-list order, so every sum runs in a fixed order and the result is as
//! deterministic as the stress). Nothing here writes to a state.
//!
//! Definitions (2D, `N` discs, `N_c` contacts, unit normal `n = l / |l|` along the branch
//! vector):
//! - porosity `1 - sum(pi r^2) / A` and void ratio `A / sum(pi r^2) - 1`, `A` the current cell
//!   area `det(Fbar) V`;
//! - coordination `2 N_c / N`; mechanical coordination `2 (N_c - N_c1) / (N - N_0 - N_1)`
//!   without the rattlers (Thornton 2000: `N_0` discs with no contact, `N_1` with one, `N_c1`
//!   the contacts of the latter, `N_1` unless two of them touch each other);
//! - fabric `F = (1/N_c) sum n n` (trace 1), principal values `f_1 >= f_2`, anisotropy
//!   `a = 2 (f_1 - f_2) / (f_1 + f_2)`, the `a` of the contact-normal density
//!   `E(theta) = (1 + a cos 2(theta - theta_a)) / (2 pi)` (Rothenburg and Bathurst 1989);
//! - sliding fraction: contacts whose tangential force is at the Coulomb cap `mu_s F_n`, the
//!   cap [`crate::contact::tangential::update`] clamps to (read with the same 1e-9 relative
//!   margin as the sliding-aware tangent);
//! - mean rotation: the mean of the disc rotations `theta`, which are 0 when the packing's
//!   discs are placed (the reference relaxation's own small rotations are included; a
//!   relaxation never returns a non-finite rotation: see [`crate::integrate::blown_up`]).

use crate::broadphase::PairList;
use crate::contact::Law;
use crate::homogenize::for_each_contact;
use cosdem_common::MicroDescriptors;

/// One contact as the descriptors see it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactSample {
    /// First disc.
    pub p: usize,
    /// Second disc.
    pub q: usize,
    /// Branch vector from `p` to `q`, x (any nonzero length: only its direction counts).
    pub lx: f64,
    /// Branch vector, y.
    pub ly: f64,
    /// Whether the tangential force is at its Coulomb limit.
    pub sliding: bool,
}

/// Descriptors of discs of radii `r` and rotations `th` (rad) in a cell of area `area`,
/// touching through `contacts` (each pair once).
///
/// Without discs or without contacts the contact-based descriptors are 0 (never NaN: they go
/// on the wire and into the outputs).
///
/// # Panics
/// When `r` and `th` differ in length or a contact names a disc beyond them (caller bugs).
pub fn describe(
    r: &[f64],
    th: &[f64],
    area: f64,
    contacts: impl IntoIterator<Item = ContactSample>,
) -> MicroDescriptors {
    assert_eq!(r.len(), th.len(), "one rotation per disc");
    let n = r.len();
    let contacts: Vec<ContactSample> = contacts.into_iter().collect();
    let mut per_disc = vec![0u32; n];
    let (mut fxx, mut fyy, mut fxy) = (0.0, 0.0, 0.0);
    let (mut nc, mut nslide) = (0u32, 0u32);
    for c in &contacts {
        per_disc[c.p] += 1;
        per_disc[c.q] += 1;
        let len = c.lx.hypot(c.ly);
        let (nx, ny) = (c.lx / len, c.ly / len);
        fxx += nx * nx;
        fyy += ny * ny;
        fxy += nx * ny;
        nc += 1;
        nslide += u32::from(c.sliding);
    }
    let mut d = MicroDescriptors::default();
    let solid: f64 = r.iter().map(|r| std::f64::consts::PI * r * r).sum();
    if area > 0.0 && solid > 0.0 {
        d.porosity = 1.0 - solid / area;
        d.void_ratio = area / solid - 1.0;
    }
    if n > 0 {
        d.coordination = 2.0 * f64::from(nc) / n as f64;
        d.mean_rotation = th.iter().fold(0.0, |s, t| s + t) / n as f64;
    }
    let n0 = per_disc.iter().filter(|&&k| k == 0).count();
    let n1 = per_disc.iter().filter(|&&k| k == 1).count();
    if n > n0 + n1 {
        // Contacts of a one-contact disc go with it (a contact between two such discs once).
        let kept = contacts.iter().filter(|c| per_disc[c.p] > 1 && per_disc[c.q] > 1).count();
        d.mechanical_coordination = 2.0 * kept as f64 / (n - n0 - n1) as f64;
    }
    if nc > 0 {
        let inv = 1.0 / f64::from(nc);
        (d.fabric_xx, d.fabric_yy, d.fabric_xy) = (fxx * inv, fyy * inv, fxy * inv);
        let (a, theta) = anisotropy(d.fabric_xx, d.fabric_yy, d.fabric_xy);
        (d.anisotropy, d.fabric_direction) = (a, theta);
        d.sliding_fraction = f64::from(nslide) * inv;
    }
    // Protobuf omits a zero `double`, so a negative zero (an underflow, a sum of negative
    // zeros) would come back positive from a worker: `+ 0.0` makes every zero positive here,
    // and the wire and the direct path agree bit for bit.
    for v in [
        &mut d.porosity,
        &mut d.void_ratio,
        &mut d.coordination,
        &mut d.mechanical_coordination,
        &mut d.fabric_xx,
        &mut d.fabric_yy,
        &mut d.fabric_xy,
        &mut d.anisotropy,
        &mut d.fabric_direction,
        &mut d.sliding_fraction,
        &mut d.mean_rotation,
    ] {
        *v += 0.0;
    }
    d
}

/// Anisotropy `a = 2 (f_1 - f_2) / (f_1 + f_2)` of the symmetric 2x2 tensor `[[fxx, fxy],
/// [fxy, fyy]]` with principal values `f_1 >= f_2` (0 for a zero trace), and the direction of
/// `f_1` in radians from x, in `(-pi/2, pi/2]` (`atan2(0, 0) = 0` for an isotropic tensor;
/// meaningless, as any direction is, when `a` is at rounding level).
pub fn anisotropy(fxx: f64, fyy: f64, fxy: f64) -> (f64, f64) {
    let trace = fxx + fyy;
    let radius = (0.5 * (fxx - fyy)).hypot(fxy);
    let a = if trace > 0.0 { 4.0 * radius / trace } else { 0.0 };
    (a, 0.5 * (2.0 * fxy).atan2(fxx - fyy))
}

/// Descriptors of a state: discs at `(x, y)` with radii `r` and rotations `th`, the active
/// contacts of `pairs` under `law` (as the homogenization counts them), current cell area
/// `area`.
pub fn of_state(
    law: &Law,
    x: &[f64],
    y: &[f64],
    r: &[f64],
    th: &[f64],
    pairs: &PairList,
    area: f64,
) -> MicroDescriptors {
    let mut contacts = Vec::with_capacity(pairs.len());
    for_each_contact(law, x, y, r, pairs, |c| {
        contacts.push(ContactSample {
            p: pairs.i[c.k] as usize,
            q: pairs.j[c.k] as usize,
            lx: c.lx,
            ly: c.ly,
            sliding: c.sliding,
        });
    });
    describe(r, th, area, contacts)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn sample(p: usize, q: usize, angle: f64, sliding: bool) -> ContactSample {
        ContactSample { p, q, lx: angle.cos(), ly: angle.sin(), sliding }
    }

    /// Three discs in a row, 0-1 and 1-2 touching along x, a third contact 1-3 along y with a
    /// fourth disc, and a fifth disc alone: every descriptor by hand. Exact sums of small
    /// binary fractions, so compared to 1e-15 (rounding of `cos(pi/2)` and the divisions).
    #[test]
    fn hand_built_discs_match_hand_counts() {
        let r = [1.0, 1.0, 1.0, 0.5, 0.5];
        let th = [0.1, -0.3, 0.2, 0.0, 0.5];
        let contacts =
            [sample(0, 1, 0.0, false), sample(1, 2, 0.0, true), sample(1, 3, 0.5 * PI, false)];
        let area = 20.0;
        let d = describe(&r, &th, area, contacts);
        let solid = PI * (3.0 + 2.0 * 0.25);
        assert!((d.porosity - (1.0 - solid / area)).abs() < 1e-15);
        assert!((d.void_ratio - (area / solid - 1.0)).abs() < 1e-15);
        // 3 contacts, 5 discs: Z = 6/5. Rattlers: disc 4 (no contact), discs 0, 2, 3 (one
        // each): Z_m = 2 (3 - 3) / (5 - 1 - 3) = 0.
        assert_eq!(d.coordination, 6.0 / 5.0);
        assert_eq!(d.mechanical_coordination, 0.0);
        // Two normals along x, one along y.
        assert!((d.fabric_xx - 2.0 / 3.0).abs() < 1e-15);
        assert!((d.fabric_yy - 1.0 / 3.0).abs() < 1e-15);
        assert!(d.fabric_xy.abs() < 1e-15);
        // f1 = 2/3, f2 = 1/3: a = 2 (1/3) / 1 = 2/3, major direction x.
        assert!((d.anisotropy - 2.0 / 3.0).abs() < 1e-15);
        assert!(d.fabric_direction.abs() < 1e-15);
        assert!((d.sliding_fraction - 1.0 / 3.0).abs() < 1e-15);
        assert!((d.mean_rotation - 0.1).abs() < 1e-15);
    }

    /// A closed triangle of three discs (three contacts, each disc with two): no rattler, so
    /// both coordination numbers are 2; the normals at 0, 60 and 120 degrees make an isotropic
    /// fabric `I/2` (three directions at 60 degrees are the smallest isotropic set in 2D).
    /// Rounding of the trigonometric values only: 1e-15.
    #[test]
    fn triangle_has_isotropic_fabric_and_no_rattlers() {
        let r = [1.0; 3];
        let contacts = [
            sample(0, 1, 0.0, false),
            sample(0, 2, PI / 3.0, false),
            sample(1, 2, 2.0 * PI / 3.0, false),
        ];
        let d = describe(&r, &[0.0; 3], 10.0, contacts);
        assert_eq!(d.coordination, 2.0);
        assert_eq!(d.mechanical_coordination, 2.0);
        assert!((d.fabric_xx - 0.5).abs() < 1e-15 && (d.fabric_yy - 0.5).abs() < 1e-15);
        assert!(d.fabric_xy.abs() < 1e-15);
        assert!(d.anisotropy < 1e-15, "a = {}", d.anisotropy);
        assert_eq!(d.sliding_fraction, 0.0);
    }

    /// The branch vector's sense and length do not matter (`n n` is even in `n`), and the
    /// principal direction of a fabric tilted by 30 degrees is 30 degrees.
    #[test]
    fn fabric_ignores_branch_sense_and_finds_the_tilt() {
        let t = PI / 6.0;
        let one = describe(&[1.0; 2], &[0.0; 2], 10.0, [sample(0, 1, t, false)]);
        let flipped = describe(
            &[1.0; 2],
            &[0.0; 2],
            10.0,
            [ContactSample { p: 0, q: 1, lx: -3.0 * t.cos(), ly: -3.0 * t.sin(), sliding: false }],
        );
        for (a, b) in [
            (one.fabric_xx, flipped.fabric_xx),
            (one.fabric_yy, flipped.fabric_yy),
            (one.fabric_xy, flipped.fabric_xy),
        ] {
            assert!((a - b).abs() < 1e-15);
        }
        // One direction: f1 = 1, f2 = 0, a = 2 (the largest value).
        assert!((one.anisotropy - 2.0).abs() < 1e-15);
        assert!((one.fabric_direction - t).abs() < 1e-15);
    }

    /// An isolated pair (a dimer) and a triangle: the dimer's two discs are rattlers and their
    /// one contact goes with them (Thornton's `N_c - N_1` would remove it twice), so the
    /// mechanical coordination is the triangle's 2 while the plain one is `2 * 4 / 5`.
    #[test]
    fn dimer_rattlers_remove_their_contact_once() {
        let contacts = [
            sample(0, 1, 0.0, false),
            sample(0, 2, PI / 3.0, false),
            sample(1, 2, 2.0 * PI / 3.0, false),
            sample(3, 4, 0.3, false),
        ];
        let d = describe(&[1.0; 5], &[0.0; 5], 30.0, contacts);
        assert_eq!(d.coordination, 8.0 / 5.0);
        assert_eq!(d.mechanical_coordination, 2.0);
    }

    /// No contacts, no discs: zeros, never NaN.
    #[test]
    fn empty_cases_are_zero_not_nan() {
        let d = describe(&[1.0, 1.0], &[0.2, 0.4], 10.0, []);
        assert_eq!((d.coordination, d.mechanical_coordination, d.anisotropy), (0.0, 0.0, 0.0));
        assert_eq!((d.fabric_xx, d.fabric_yy, d.sliding_fraction), (0.0, 0.0, 0.0));
        assert!((d.mean_rotation - 0.3).abs() < 1e-15);
        let e = describe(&[], &[], 0.0, []);
        assert_eq!(e, MicroDescriptors::default());
        // Negative zeros in, no negative zero out (the wire could not carry its sign).
        let z = describe(&[1.0], &[-0.0], 10.0, []);
        assert_eq!(z.mean_rotation.to_bits(), 0.0f64.to_bits());
    }
}
