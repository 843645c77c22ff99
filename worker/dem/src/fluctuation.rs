//! The fluctuation field (Eq. 35) and the affine fit of a deformed assembly (theory.md §8).
//!
//! **Fluctuation.** The part of each disc's displacement that the macro deformation does not
//! explain: `u_R,q = (x_q - X_q) - (Fbar - I)(X_q - X_c)`. Written into particle snapshots and
//! drawn as arrows.
//!
//! **Affine fit.** The deformation the discs actually follow: the least-squares fit
//! `x = c + G (X - X_c)` over the discs outside the boundary layer (all discs of a periodic
//! cell). With a penalty boundary `G` falls a little short of the imposed `Fbar`; the tests
//! that compare a measured stiffness with a closed form use the strain of `G`.
//!
//! Both are pure functions of the reference centres `X_q` (`x0`, `y0`), the reference centre
//! `X_c` and the current centres `x_q` (`x`, `y`); [`crate::Assembly::fluctuation`] and
//! [`crate::Assembly::affine_fit`] call them on an assembly's state.

use crate::boundary::{mat_inv, mat_mul};

/// Fluctuation of every disc, Eq. 35: `u_R,q = (x_q - X_q) - (f - I)(X_q - X_c)`, with
/// `X_q = (x0[q], y0[q])` and `x_q = (x[q], y[q])`.
pub fn fluctuation(
    f: &[[f64; 2]; 2],
    x0: &[f64],
    y0: &[f64],
    xc: [f64; 2],
    x: &[f64],
    y: &[f64],
) -> Vec<[f64; 2]> {
    (0..x0.len())
        .map(|q| {
            let (dx, dy) = (x0[q] - xc[0], y0[q] - xc[1]);
            let ux = x[q] - x0[q];
            let uy = y[q] - y0[q];
            [ux - ((f[0][0] - 1.0) * dx + f[0][1] * dy), uy - (f[1][0] * dx + (f[1][1] - 1.0) * dy)]
        })
        .collect()
}

/// Best affine fit `x = c + G (X - X_c)` of the discs not listed in `boundary` (the boundary
/// layer of a penalty boundary; empty for a periodic cell); returns `G`, the measured
/// deformation gradient.
pub fn affine_fit(
    x0: &[f64],
    y0: &[f64],
    xc: [f64; 2],
    boundary: &[u32],
    x: &[f64],
    y: &[f64],
) -> [[f64; 2]; 2] {
    let discs = x0.len();
    let mut inb = vec![false; discs];
    for &q in boundary {
        inb[q as usize] = true;
    }
    let (mut n, mut mx, mut my, mut mxx, mut myy) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for q in 0..discs {
        if inb[q] {
            continue;
        }
        n += 1.0;
        mx += x0[q] - xc[0];
        my += y0[q] - xc[1];
        mxx += x[q];
        myy += y[q];
    }
    let (mx, my, mxx, myy) = (mx / n, my / n, mxx / n, myy / n);
    let (mut a, mut b, mut c) = (0.0, 0.0, 0.0);
    let mut rhs = [[0.0; 2]; 2];
    for q in 0..discs {
        if inb[q] {
            continue;
        }
        let (px, py) = (x0[q] - xc[0] - mx, y0[q] - xc[1] - my);
        let (ux, uy) = (x[q] - mxx, y[q] - myy);
        a += px * px;
        b += px * py;
        c += py * py;
        rhs[0][0] += ux * px;
        rhs[0][1] += ux * py;
        rhs[1][0] += uy * px;
        rhs[1][1] += uy * py;
    }
    let inv = mat_inv(&[[a, b], [b, c]]);
    mat_mul(&rhs, &inv)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 4 x 3 grid of reference centres about `X_c = (0.5, -0.2)` (made-up but generic: no
    /// symmetry that could hide a swapped index).
    fn grid() -> (Vec<f64>, Vec<f64>, [f64; 2]) {
        let xc = [0.5, -0.2];
        let (mut x0, mut y0) = (Vec::new(), Vec::new());
        for i in 0..4 {
            for j in 0..3 {
                x0.push(xc[0] - 0.3 + 0.2 * f64::from(i) + 0.01 * f64::from(j));
                y0.push(xc[1] - 0.2 + 0.2 * f64::from(j));
            }
        }
        (x0, y0, xc)
    }

    /// The centres `x = X + t + (g - I)(X - X_c)`: an exactly affine image of the grid.
    fn affine(g: &[[f64; 2]; 2], t: [f64; 2]) -> (Vec<f64>, Vec<f64>) {
        let (x0, y0, xc) = grid();
        let x = (0..x0.len())
            .map(|q| {
                let (dx, dy) = (x0[q] - xc[0], y0[q] - xc[1]);
                x0[q] + t[0] + (g[0][0] - 1.0) * dx + g[0][1] * dy
            })
            .collect();
        let y = (0..x0.len())
            .map(|q| {
                let (dx, dy) = (x0[q] - xc[0], y0[q] - xc[1]);
                y0[q] + t[1] + g[1][0] * dx + (g[1][1] - 1.0) * dy
            })
            .collect();
        (x, y)
    }

    const G: [[f64; 2]; 2] = [[0.98, 0.013], [-0.007, 1.021]];

    /// An affine image with no translation has no fluctuation: every component is a
    /// difference of equal terms of size ~0.3 computed in another order, so it is zero to a
    /// few ulps of 0.3 (1e-15).
    #[test]
    fn an_affine_image_has_no_fluctuation() {
        let (x0, y0, xc) = grid();
        let (x, y) = affine(&G, [0.0, 0.0]);
        for u in fluctuation(&G, &x0, &y0, xc, &x, &y) {
            assert!(u[0].abs() < 1e-15 && u[1].abs() < 1e-15, "{u:?}");
        }
    }

    /// A rigid translation on top of the affine image is all fluctuation (Eq. 35 removes only
    /// `(F - I)(X - X_c)`): each disc's `u_R` is the translation, to a few ulps of 0.3.
    #[test]
    fn a_translation_is_fluctuation() {
        let (x0, y0, xc) = grid();
        let t = [1e-3, -2e-3];
        let (x, y) = affine(&G, t);
        for u in fluctuation(&G, &x0, &y0, xc, &x, &y) {
            assert!((u[0] - t[0]).abs() < 1e-15 && (u[1] - t[1]).abs() < 1e-15, "{u:?}");
        }
    }

    /// The fit of an affine image (translated, so the fit's centring is exercised) recovers
    /// its gradient; the least-squares solve of a well-conditioned 2x2 system over twelve
    /// points loses a few digits at most, hence 1e-12.
    #[test]
    fn the_fit_of_an_affine_image_is_its_gradient() {
        let (x0, y0, xc) = grid();
        let (x, y) = affine(&G, [0.01, 0.02]);
        let g = affine_fit(&x0, &y0, xc, &[], &x, &y);
        for i in 0..2 {
            for j in 0..2 {
                assert!((g[i][j] - G[i][j]).abs() < 1e-12, "{g:?}");
            }
        }
    }

    /// Boundary discs are left out of the fit: moving them anywhere does not change `G` (bit
    /// for bit: they are skipped, not weighted).
    #[test]
    fn the_fit_leaves_the_boundary_layer_out() {
        let (x0, y0, xc) = grid();
        let (x, y) = affine(&G, [0.0, 0.0]);
        let boundary = [0, 11];
        let g = affine_fit(&x0, &y0, xc, &boundary, &x, &y);
        let (mut xm, mut ym) = (x.clone(), y.clone());
        xm[0] += 0.3;
        ym[11] -= 0.4;
        let gm = affine_fit(&x0, &y0, xc, &boundary, &xm, &ym);
        assert_eq!(g.map(|r| r.map(f64::to_bits)), gm.map(|r| r.map(f64::to_bits)));
    }
}
