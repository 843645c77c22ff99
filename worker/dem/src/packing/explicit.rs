//! A given disc list (read from a packing file on the master, or written out in a spec): its
//! checks and the overlap search.
//!
//! The discs are the reference state as they are: no compression, no relaxation before the
//! first load (deterministic: the same list builds the same assembly, bit for bit). For a
//! penalty boundary the rest points of the boundary layer are placed so that the given
//! configuration is in equilibrium at its reference (as for a random packing, see
//! [`super::random`]); for a configuration without overlaps that changes nothing.

use super::Packing;

/// Largest overlap of two discs accepted, as a fraction of the smaller radius: 1e-2.
///
/// Touching discs written at full precision overlap by rounding only (1e-16 of a radius),
/// files printed at 6 or 7 significant digits by about 1e-6. A packing in equilibrium at a
/// confining stress `p` overlaps by about `2 r p / k_n`: 3e-3 of the radius at the paper's
/// `k_n = 6.7e7 N/m` and 100 kPa, so 1e-3 would refuse cosdem's own random packings; 1e-2
/// keeps them (up to about 300 kPa) and still refuses discs placed on top of each other, a
/// unit mismatch between centres and radii, or a 3D packing flattened into a plane.
pub const OVERLAP_TOLERANCE: f64 = 1e-2;

/// Two discs that overlap too much.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Overlap {
    /// The first disc (`i < j`).
    pub i: usize,
    /// The second disc.
    pub j: usize,
    /// `r_i + r_j - |x_j - x_i|` (m).
    pub overlap: f64,
}

/// The first pair (smallest `j`, then smallest `i`) whose overlap exceeds
/// [`OVERLAP_TOLERANCE`] of the smaller radius; centres in `[0, lx] x [0, ly]`, seen through
/// the periodic cell when `periodic`. A cell grid of side at least one largest diameter:
/// linear in the disc count.
pub fn first_overlap(
    x: &[f64],
    y: &[f64],
    r: &[f64],
    lx: f64,
    ly: f64,
    periodic: bool,
) -> Option<Overlap> {
    let n = r.len();
    let r_max = r.iter().fold(0.0f64, |a, &b| a.max(b));
    if n < 2 || r_max.is_nan() || r_max <= 0.0 {
        return None;
    }
    let cells = |l: f64| ((l / (2.0 * r_max)).floor().clamp(1.0, 4096.0)) as usize;
    let (nx, ny) = (cells(lx), cells(ly));
    let cell_of = |v: f64, l: f64, m: usize| {
        let v = if periodic { v - (v / l).floor() * l } else { v };
        (((v / l) * m as f64).floor().max(0.0) as usize).min(m - 1)
    };
    let mut head = vec![u32::MAX; nx * ny];
    let mut next = vec![u32::MAX; n];
    for k in (0..n).rev() {
        let c = cell_of(y[k], ly, ny) * nx + cell_of(x[k], lx, nx);
        next[k] = head[c];
        head[c] = k as u32;
    }
    let mut found: Option<Overlap> = None;
    for j in 0..n {
        let (cx, cy) = (cell_of(x[j], lx, nx) as isize, cell_of(y[j], ly, ny) as isize);
        let mut seen = [usize::MAX; 9];
        for (s, (dx, dy)) in
            (-1..=1isize).flat_map(|a| (-1..=1isize).map(move |b| (a, b))).enumerate()
        {
            let (mut ix, mut iy) = (cx + dx, cy + dy);
            if periodic {
                ix = ix.rem_euclid(nx as isize);
                iy = iy.rem_euclid(ny as isize);
            } else if ix < 0 || iy < 0 || ix >= nx as isize || iy >= ny as isize {
                continue;
            }
            let c = iy as usize * nx + ix as usize;
            if seen.contains(&c) {
                continue; // a small periodic grid wraps onto a cell already visited
            }
            seen[s] = c;
            let mut i = head[c];
            while i != u32::MAX {
                let k = i as usize;
                i = next[k];
                if k >= j {
                    continue;
                }
                let (mut ddx, mut ddy) = (x[j] - x[k], y[j] - y[k]);
                if periodic {
                    ddx -= (ddx / lx).round() * lx;
                    ddy -= (ddy / ly).round() * ly;
                }
                let overlap = r[j] + r[k] - ddx.hypot(ddy);
                if overlap > OVERLAP_TOLERANCE * r[j].min(r[k])
                    && found.is_none_or(|f| f.j == j && k < f.i)
                {
                    found = Some(Overlap { i: k, j, overlap });
                }
            }
        }
        if found.is_some() {
            return found;
        }
    }
    None
}

impl Packing {
    /// The packing of an explicit disc list (copied as it is: file order, no sorting).
    pub fn explicit(x: &[f64], y: &[f64], r: &[f64], lx: f64, ly: f64) -> Packing {
        Packing { x: x.to_vec(), y: y.to_vec(), r: r.to_vec(), lx, ly }
    }

    /// The packing of an assembly's committed state (what a checkpoint holds): its centres
    /// and radii, and as region the bounding box of the reference region mapped by the
    /// committed `Fbar` (about `X_c` for a penalty boundary, the cell `H = Fbar H_0` for a
    /// periodic one), shifted to the origin. At the reference state that is the reference
    /// region itself, bit for bit: read back, the file builds the same assembly. Periodic
    /// centres farther than one largest diameter out of the region are wrapped into it (the
    /// same specimen). A sheared state has no rectangular image: its bounding box is a
    /// picture of the state, not a cell to build from.
    pub fn committed(a: &crate::Assembly) -> Packing {
        let refc = a.reference();
        let st = a.committed();
        let f = st.target.f;
        let (mut x, mut y) = (st.dynamics.x.clone(), st.dynamics.y.clone());
        let periodic = matches!(a.spec().boundary, crate::BoundarySpec::Periodic);
        let origin = if periodic { [0.0, 0.0] } else { refc.xc };
        let map = |cx: f64, cy: f64| {
            let (dx, dy) = (cx - origin[0], cy - origin[1]);
            [origin[0] + f[0][0] * dx + f[0][1] * dy, origin[1] + f[1][0] * dx + f[1][1] * dy]
        };
        let mut b = [f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY];
        for (cx, cy) in [(0.0, 0.0), (refc.lx, 0.0), (0.0, refc.ly), (refc.lx, refc.ly)] {
            let [px, py] = map(cx, cy);
            b = [b[0].min(px), b[1].max(px), b[2].min(py), b[3].max(py)];
        }
        let (lx, ly) = (b[1] - b[0], b[3] - b[2]);
        x.iter_mut().for_each(|v| *v -= b[0]);
        y.iter_mut().for_each(|v| *v -= b[2]);
        if periodic {
            let d = 2.0 * refc.r_max;
            let wrap = |v: &mut f64, l: f64| {
                if !(-d..=l + d).contains(v) {
                    *v -= (*v / l).floor() * l;
                }
            };
            x.iter_mut().for_each(|v| wrap(v, lx));
            y.iter_mut().for_each(|v| wrap(v, ly));
        }
        Packing { x, y, r: refc.r.clone(), lx, ly }
    }

    /// Area fraction of the discs in the region, `sum pi r^2 / (lx ly)`.
    pub fn solid_fraction(&self) -> f64 {
        self.r.iter().map(|r| std::f64::consts::PI * r * r).sum::<f64>() / self.area()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Discs on a square lattice of spacing `2 r (1 - e)`: overlap `2 r e`.
    fn lattice(n: usize, r: f64, e: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>, f64) {
        let s = 2.0 * r * (1.0 - e);
        let (mut x, mut y) = (Vec::new(), Vec::new());
        for j in 0..n {
            for i in 0..n {
                x.push(r + s * i as f64);
                y.push(r + s * j as f64);
            }
        }
        let l = s * n as f64;
        (x, y, vec![r; n * n], l)
    }

    /// Touching discs pass; an overlap of 2e-2 r (beyond the 1e-2 tolerance) between two
    /// chosen discs is found, and named as the pair it is, in a 10 000-disc grid.
    #[test]
    fn the_grid_finds_the_one_overlap() {
        let (mut x, y, r, l) = lattice(100, 1.0, 0.0);
        assert_eq!(first_overlap(&x, &y, &r, l, l, false), None);
        assert_eq!(first_overlap(&x, &y, &r, l, l, true), None);
        x[5051] -= 0.02; // disc (51, 50) towards (50, 50): overlap 0.02 = 2e-2 r
        let o = first_overlap(&x, &y, &r, l, l, false).unwrap();
        assert_eq!((o.i, o.j), (5050, 5051));
        assert!((o.overlap - 0.02).abs() < 1e-12, "{o:?}");
    }

    /// Across the cell faces: the discs of the first and last columns touch through the
    /// periodic cell, and overlap there when the cell is shrunk, seen only as periodic.
    #[test]
    fn periodic_images_count_only_when_periodic() {
        let (x, y, r, l) = lattice(6, 1.0, 0.0);
        let short = l - 0.05;
        assert_eq!(first_overlap(&x, &y, &r, short, l, false), None);
        let o = first_overlap(&x, &y, &r, short, l, true).unwrap();
        assert_eq!((o.i, o.j), (0, 5), "{o:?}");
        assert!((o.overlap - 0.05).abs() < 1e-12);
    }

    /// The solid fraction of four discs of radius 1 in a 4 x 4 square is pi / 4.
    #[test]
    fn solid_fraction_of_a_square_lattice() {
        let p =
            Packing::explicit(&[1.0, 3.0, 1.0, 3.0], &[1.0, 1.0, 3.0, 3.0], &[1.0; 4], 4.0, 4.0);
        assert!((p.solid_fraction() - std::f64::consts::FRAC_PI_4).abs() < 1e-15);
    }
}
