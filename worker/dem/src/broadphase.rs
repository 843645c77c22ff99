//! Broad phase linear in N: a cell grid builds a Verlet pair list with a skin; the list is
//! rebuilt only when some disc has moved more than half the skin since the last build.
//!
//! The pair list also owns the per-contact histories (tangential spring `fs`, rolling spring
//! `hr`), carried over by key `(i, j)` at each rebuild. Pairs are sorted by `(i, j)`, `i < j`,
//! so the force summation order is a pure function of the state (bit-reproducible).

use serde::{Deserialize, Serialize};

/// Geometry of the domain seen by the broad phase.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Domain {
    /// Open plane (penalty boundary).
    Open,
    /// Periodic cell `x = H s`, `s` in `[0,1)^2`; `h[a][b]` row a, column b: the columns are
    /// the cell vectors.
    Periodic {
        /// Cell matrix.
        h: [[f64; 2]; 2],
    },
}

/// Verlet pair list with per-pair contact histories.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PairList {
    /// First disc of each pair.
    pub i: Vec<u32>,
    /// Second disc of each pair (`j > i`).
    pub j: Vec<u32>,
    /// Periodic image offset added to `x_j - x_i` (empty for an open domain).
    pub ox: Vec<f64>,
    /// Periodic image offset, y (empty for an open domain).
    pub oy: Vec<f64>,
    /// Tangential spring history (N), scalar in the contact frame.
    pub fs: Vec<f64>,
    /// Rolling spring history (N m).
    pub hr: Vec<f64>,
    /// Positions at the last build, x.
    pub xb: Vec<f64>,
    /// Positions at the last build, y.
    pub yb: Vec<f64>,
    /// Skin used by the last build (m).
    pub skin: f64,
}

impl PairList {
    /// Number of pairs.
    pub fn len(&self) -> usize {
        self.i.len()
    }

    /// True when there are no pairs.
    pub fn is_empty(&self) -> bool {
        self.i.is_empty()
    }

    /// Largest squared displacement since the last build.
    pub fn max_disp2(&self, x: &[f64], y: &[f64]) -> f64 {
        let mut m = 0.0f64;
        for k in 0..x.len() {
            let dx = x[k] - self.xb[k];
            let dy = y[k] - self.yb[k];
            m = m.max(dx.mul_add(dx, dy * dy));
        }
        m
    }
}

fn inv2(h: &[[f64; 2]; 2]) -> [[f64; 2]; 2] {
    let det = h[0][0] * h[1][1] - h[0][1] * h[1][0];
    [[h[1][1] / det, -h[0][1] / det], [-h[1][0] / det, h[0][0] / det]]
}

/// Builds a new pair list (cutoff `r_i + r_j + skin`), carrying the histories of `old` over.
pub fn build(
    x: &[f64],
    y: &[f64],
    r: &[f64],
    skin: f64,
    domain: Domain,
    old: &PairList,
) -> PairList {
    let n = x.len();
    let rmax = r.iter().fold(0.0f64, |a, &b| a.max(b));
    let cut = 2.0 * rmax + skin;
    let mut pi: Vec<u32> = Vec::with_capacity(old.len().max(4 * n));
    let mut pj: Vec<u32> = Vec::with_capacity(old.len().max(4 * n));
    let mut ox = Vec::new();
    let mut oy = Vec::new();
    let periodic = matches!(domain, Domain::Periodic { .. });
    // Cell coordinates: open domain -> bounding box; periodic -> fractional coordinates.
    let (u, v, ncx, ncy, hinv, h) = match domain {
        Domain::Open => {
            let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
            for k in 0..n {
                x0 = x0.min(x[k]);
                x1 = x1.max(x[k]);
                y0 = y0.min(y[k]);
                y1 = y1.max(y[k]);
            }
            // Cap the grid so a blown-up state cannot allocate without bound.
            // A non-finite extent (a state that blew up between two divergence checks) gets
            // one cell: the relaxation reports the divergence at its next check.
            let cap = (4.0 * (n as f64).sqrt() + 4.0).min(4096.0);
            let cells = |extent: f64| -> usize {
                let c = (extent / cut).floor();
                if c.is_finite() { c.clamp(1.0, cap) as usize } else { 1 }
            };
            let cx = cells(x1 - x0);
            let cy = cells(y1 - y0);
            let sx = cx as f64 / (x1 - x0).max(f64::MIN_POSITIVE);
            let sy = cy as f64 / (y1 - y0).max(f64::MIN_POSITIVE);
            let u: Vec<f64> = x.iter().map(|&xi| ((xi - x0) * sx).min(cx as f64 - 0.5)).collect();
            let v: Vec<f64> = y.iter().map(|&yi| ((yi - y0) * sy).min(cy as f64 - 0.5)).collect();
            (u, v, cx, cy, [[1.0, 0.0], [0.0, 1.0]], [[1.0, 0.0], [0.0, 1.0]])
        }
        Domain::Periodic { h } => {
            let hi = inv2(&h);
            let area = (h[0][0] * h[1][1] - h[0][1] * h[1][0]).abs();
            let a1 = h[0][0].hypot(h[1][0]);
            let a2 = h[0][1].hypot(h[1][1]);
            let w1 = area / a2; // distance between the faces spanned by a2
            let w2 = area / a1;
            // NaN casts to 0 cells: the all-pairs loop below takes over.
            let cx = ((w1 / cut).floor() as usize).min(4096);
            let cy = ((w2 / cut).floor() as usize).min(4096);
            let mut u = Vec::with_capacity(n);
            let mut v = Vec::with_capacity(n);
            for k in 0..n {
                let s1 = hi[0][0].mul_add(x[k], hi[0][1] * y[k]);
                let s2 = hi[1][0].mul_add(x[k], hi[1][1] * y[k]);
                u.push((s1 - s1.floor()) * cx as f64);
                v.push((s2 - s2.floor()) * cy as f64);
            }
            (u, v, cx, cy, hi, h)
        }
    };
    let min_image = |dx: &mut f64, dy: &mut f64| -> (f64, f64) {
        let s1 = hinv[0][0].mul_add(*dx, hinv[0][1] * *dy);
        let s2 = hinv[1][0].mul_add(*dx, hinv[1][1] * *dy);
        let k1 = -s1.round();
        let k2 = -s2.round();
        let ofx = h[0][0].mul_add(k1, h[0][1] * k2);
        let ofy = h[1][0].mul_add(k1, h[1][1] * k2);
        *dx += ofx;
        *dy += ofy;
        (ofx, ofy)
    };
    let push = |i: usize,
                j: usize,
                pi: &mut Vec<u32>,
                pj: &mut Vec<u32>,
                ox: &mut Vec<f64>,
                oy: &mut Vec<f64>| {
        let mut dx = x[j] - x[i];
        let mut dy = y[j] - y[i];
        let (ofx, ofy) = if periodic { min_image(&mut dx, &mut dy) } else { (0.0, 0.0) };
        let c = r[i] + r[j] + skin;
        if dx.mul_add(dx, dy * dy) < c * c {
            pi.push(i as u32);
            pj.push(j as u32);
            if periodic {
                ox.push(ofx);
                oy.push(ofy);
            }
        }
    };
    let small_periodic = periodic && (ncx < 3 || ncy < 3);
    if small_periodic || n < 32 {
        for i in 0..n {
            for j in i + 1..n {
                push(i, j, &mut pi, &mut pj, &mut ox, &mut oy);
            }
        }
    } else {
        // Counting sort of discs into cells (CSR).
        let ncell = ncx * ncy;
        let cell_of = |k: usize| -> usize {
            let cx = (u[k] as usize).min(ncx - 1);
            let cy = (v[k] as usize).min(ncy - 1);
            cy * ncx + cx
        };
        let mut start = vec![0u32; ncell + 1];
        let cells: Vec<usize> = (0..n).map(cell_of).collect();
        for &c in &cells {
            start[c + 1] += 1;
        }
        for c in 0..ncell {
            start[c + 1] += start[c];
        }
        let mut fill = start.clone();
        let mut items = vec![0u32; n];
        for k in 0..n {
            let c = cells[k];
            items[fill[c] as usize] = k as u32;
            fill[c] += 1;
        }
        let mut cand: Vec<u32> = Vec::with_capacity(32);
        for i in 0..n {
            let c = cells[i];
            let (cx, cy) = ((c % ncx) as isize, (c / ncx) as isize);
            cand.clear();
            for ddy in -1isize..=1 {
                let mut yy = cy + ddy;
                if periodic {
                    yy = yy.rem_euclid(ncy as isize);
                } else if yy < 0 || yy >= ncy as isize {
                    continue;
                }
                for ddx in -1isize..=1 {
                    let mut xx = cx + ddx;
                    if periodic {
                        xx = xx.rem_euclid(ncx as isize);
                    } else if xx < 0 || xx >= ncx as isize {
                        continue;
                    }
                    let cc = yy as usize * ncx + xx as usize;
                    for &j in &items[start[cc] as usize..start[cc + 1] as usize] {
                        if j as usize > i {
                            cand.push(j);
                        }
                    }
                }
            }
            cand.sort_unstable();
            for &j in &cand {
                push(i, j as usize, &mut pi, &mut pj, &mut ox, &mut oy);
            }
        }
    }
    // Carry histories over by key (both lists sorted by (i, j)).
    let m = pi.len();
    let mut fs = vec![0.0; m];
    let mut hr = vec![0.0; m];
    let mut o = 0usize;
    for k in 0..m {
        let key = ((pi[k] as u64) << 32) | pj[k] as u64;
        while o < old.len() && (((old.i[o] as u64) << 32) | old.j[o] as u64) < key {
            o += 1;
        }
        if o < old.len() && old.i[o] == pi[k] && old.j[o] == pj[k] {
            fs[k] = old.fs[o];
            hr[k] = old.hr[o];
        }
    }
    PairList { i: pi, j: pj, ox, oy, fs, hr, xb: x.to_vec(), yb: y.to_vec(), skin }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A state that blew up between two divergence checks (NaN and infinite centres) still
    /// builds a list (the relaxation then reports the divergence): no panic from the grid.
    #[test]
    fn non_finite_positions_do_not_panic() {
        let n = 40;
        let mut x: Vec<f64> = (0..n).map(|k| k as f64 * 0.01).collect();
        let y = x.clone();
        x[3] = f64::NAN;
        x[7] = f64::INFINITY;
        x[8] = f64::NEG_INFINITY;
        let r = vec![0.005; n];
        let _ = build(&x, &y, &r, 0.001, Domain::Open, &PairList::default());
        let h = [[f64::NAN, 0.0], [0.0, 1.0]];
        let _ = build(&x, &y, &r, 0.001, Domain::Periodic { h }, &PairList::default());
    }
}
