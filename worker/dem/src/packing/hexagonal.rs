use super::Packing;

/// Hexagonal packing of discs of radius `r` in an `l` x `l` square, touching neighbours
/// (centre spacing exactly `2 r`), the lattice centred in the square. Rows are horizontal.
/// With `r = 5 mm`, `l = 0.1 m`: 105 discs.
pub fn square(r: f64, l: f64) -> Packing {
    let dy = 3f64.sqrt() * r;
    let n_row = ((l - 2.0 * r) / dy).floor() as usize + 1;
    let mut x = Vec::new();
    let mut y = Vec::new();
    for j in 0..n_row {
        let off = if j % 2 == 1 { r } else { 0.0 };
        let n_col = ((l - 2.0 * r - off) / (2.0 * r)).floor() as usize + 1;
        for i in 0..n_col {
            x.push(off + 2.0 * r * i as f64);
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
    Packing { x, y, r: vec![r; n], lx: l, ly: l }
}

/// Periodic hexagonal packing closest to an `l` x `l` square: `n_c = round(l / 2r)` columns
/// by an even number `n_r = 2 round(l / (2 sqrt(3) r))` of rows, cell `2 r n_c` by
/// `sqrt(3) r n_r`. Every disc has six touching neighbours.
pub fn periodic(r: f64, l: f64) -> Packing {
    let dy = 3f64.sqrt() * r;
    let n_col = ((l / (2.0 * r)).round() as usize).max(4);
    let n_row = (2 * (l / (2.0 * dy)).round() as usize).max(4);
    let mut x = Vec::with_capacity(n_col * n_row);
    let mut y = Vec::with_capacity(n_col * n_row);
    for j in 0..n_row {
        let off = if j % 2 == 1 { r } else { 0.0 };
        for i in 0..n_col {
            x.push(off + r + 2.0 * r * i as f64);
            y.push(dy * (j as f64 + 0.5));
        }
    }
    let n = x.len();
    Packing { x, y, r: vec![r; n], lx: 2.0 * r * n_col as f64, ly: dy * n_row as f64 }
}
