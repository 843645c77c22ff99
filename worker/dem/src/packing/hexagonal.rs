use super::Packing;
use crate::spec::{Lattice, LatticeOrientation};

/// Lattice sites at `spacing` that fit in `extent` (from the first centre to the last), one
/// more than the whole spacings in it. A side meant as a whole number of spacings is often a
/// rounding below it (`sqrt(0.0784)` = 0.27999999999999997 m): the quotient is snapped up
/// when it is within 1e-9 of the next whole number, so such a side holds its last row.
pub fn sites(extent: f64, spacing: f64) -> usize {
    ((extent / spacing + 1e-9).floor() as usize).saturating_add(1)
}

/// The rows of [`square`]: their number, the discs in an even row (starting at the left) and
/// in an odd row (shifted by half a spacing), before any turn. What
/// [`crate::AssemblySpec::disc_count_hint`] counts without building the packing.
pub fn square_rows(r: f64, l: f64, lattice: Lattice) -> (usize, usize, usize) {
    let h = r * (1.0 - lattice.overlap);
    let dy = 3f64.sqrt() * h;
    let n_row = sites(l - 2.0 * r, dy);
    (n_row, sites(l - 2.0 * r, 2.0 * h), sites(l - 2.0 * r - h, 2.0 * h))
}

/// Hexagonal packing of discs of radius `r` in an `l` x `l` square, the lattice centred in
/// the square, neighbours' centres `2 r (1 - overlap)` apart (touching when `overlap` is 0).
/// Rows run along x for [`LatticeOrientation::Rows`] (one contact family along x, the others
/// at 60 and 120 degrees); [`LatticeOrientation::Columns`] turns the lattice by 90 degrees
/// (one contact family along y). With `r = 5 mm`, `l = 0.1 m`: 105 discs.
pub fn square(r: f64, l: f64, lattice: Lattice) -> Packing {
    let h = r * (1.0 - lattice.overlap);
    let dy = 3f64.sqrt() * h;
    let (n_row, even, odd) = square_rows(r, l, lattice);
    let mut x = Vec::new();
    let mut y = Vec::new();
    for j in 0..n_row {
        let (off, n_col) = if j % 2 == 1 { (h, odd) } else { (0.0, even) };
        for i in 0..n_col {
            x.push(off + 2.0 * h * i as f64);
            y.push(dy * j as f64);
        }
    }
    let (x0, x1) = x.iter().fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    let (y0, y1) = y.iter().fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    let sx = 0.5 * l - 0.5 * (x0 + x1);
    let sy = 0.5 * l - 0.5 * (y0 + y1);
    x.iter_mut().for_each(|v| *v += sx);
    y.iter_mut().for_each(|v| *v += sy);
    let n = x.len();
    let p = Packing { x, y, r: vec![r; n], lx: l, ly: l };
    turned(p, lattice.orientation)
}

/// The columns and rows of [`periodic`]: `round(l / s)` columns (at least 4) by an even
/// number `2 round(l / (2 sqrt(3) s / 2))` of rows (at least 4), `s` the centre spacing.
pub fn periodic_grid(r: f64, l: f64, lattice: Lattice) -> (usize, usize) {
    let h = r * (1.0 - lattice.overlap);
    let dy = 3f64.sqrt() * h;
    let n_col = ((l / (2.0 * h)).round() as usize).max(4);
    let n_row = ((l / (2.0 * dy)).round() as usize).saturating_mul(2).max(4);
    (n_col, n_row)
}

/// Periodic hexagonal packing closest to an `l` x `l` square: the grid of [`periodic_grid`],
/// cell `s n_c` by `sqrt(3) s n_r / 2` with `s = 2 r (1 - overlap)` the centre spacing (turned
/// by 90 degrees, cell and all, for [`LatticeOrientation::Columns`]). Every disc has six
/// neighbours at `s`.
pub fn periodic(r: f64, l: f64, lattice: Lattice) -> Packing {
    let h = r * (1.0 - lattice.overlap);
    let dy = 3f64.sqrt() * h;
    let (n_col, n_row) = periodic_grid(r, l, lattice);
    let mut x = Vec::with_capacity(n_col * n_row);
    let mut y = Vec::with_capacity(n_col * n_row);
    for j in 0..n_row {
        let off = if j % 2 == 1 { h } else { 0.0 };
        for i in 0..n_col {
            x.push(off + h + 2.0 * h * i as f64);
            y.push(dy * (j as f64 + 0.5));
        }
    }
    let n = x.len();
    let p = Packing { x, y, r: vec![r; n], lx: 2.0 * h * n_col as f64, ly: dy * n_row as f64 };
    turned(p, lattice.orientation)
}

/// `p` as built (rows along x), or turned by 90 degrees: x and y swapped, region and all
/// (a reflection about the diagonal, which maps the lattice onto its 90-degree turn).
fn turned(p: Packing, orientation: LatticeOrientation) -> Packing {
    match orientation {
        LatticeOrientation::Rows => p,
        LatticeOrientation::Columns => Packing { x: p.y, y: p.x, r: p.r, lx: p.ly, ly: p.lx },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lattice(orientation: LatticeOrientation, overlap: f64) -> Lattice {
        Lattice { orientation, overlap }
    }

    /// The square of side sqrt(0.0784) m = 0.27999999999999997 m holds 880 discs of 5 mm,
    /// as the square of 0.28 m does (before the snap its quotient 25.999999999999996 was
    /// floored to 25 columns: 864 discs), and side 0.15 m 247 (was 238).
    #[test]
    fn a_side_a_rounding_below_whole_spacings_holds_its_last_row() {
        let rows = lattice(LatticeOrientation::Rows, 0.0);
        assert_eq!(square(0.005, 0.0784f64.sqrt(), rows).x.len(), 880);
        assert_eq!(square(0.005, 0.28, rows).x.len(), 880);
        assert_eq!(square(0.005, 0.15, rows).x.len(), 247);
        assert_eq!(square(0.005, 0.1, rows).x.len(), 105);
    }

    /// Turned by 90 degrees, every disc's neighbours at the spacing lie at 90, 30 and 150
    /// degrees (one family along y), none along x; the count and the region are those of the
    /// unturned lattice, transposed. With an overlap the spacing is `2 r (1 - overlap)`.
    #[test]
    fn the_turned_lattice_has_a_contact_family_along_y() {
        for overlap in [0.0, 0.01] {
            for (name, p, q) in [
                (
                    "square",
                    square(0.005, 0.1, lattice(LatticeOrientation::Columns, overlap)),
                    square(0.005, 0.1, lattice(LatticeOrientation::Rows, overlap)),
                ),
                (
                    "periodic",
                    periodic(0.005, 0.1, lattice(LatticeOrientation::Columns, overlap)),
                    periodic(0.005, 0.1, lattice(LatticeOrientation::Rows, overlap)),
                ),
            ] {
                assert_eq!((p.x.len(), p.lx, p.ly), (q.x.len(), q.ly, q.lx), "{name}");
                let s = 0.01 * (1.0 - overlap);
                let mut angles = std::collections::BTreeSet::new();
                for i in 0..p.x.len() {
                    for j in 0..p.x.len() {
                        let (dx, dy) = (p.x[j] - p.x[i], p.y[j] - p.y[i]);
                        if i != j && ((dx * dx + dy * dy).sqrt() - s).abs() < 1e-9 {
                            let a = dy.atan2(dx).to_degrees().rem_euclid(180.0);
                            angles.insert((a.round() as i64) % 180);
                        }
                    }
                }
                assert_eq!(angles.into_iter().collect::<Vec<_>>(), vec![30, 90, 150], "{name}");
            }
        }
    }
}
