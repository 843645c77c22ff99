//! The cell-grid broad phase finds exactly the pairs a brute-force search finds.

use cosdem_dem::broadphase::{Domain, PairList, build};

fn lcg(s: &mut u64) -> f64 {
    *s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
    (*s >> 11) as f64 / (1u64 << 53) as f64
}

/// 600 random polydisperse discs in an open domain and in a sheared periodic cell: the grid
/// list (sorted by (i, j)) equals the O(N^2) minimum-image list, offsets included (exact: both
/// compute the same expressions), and histories carry over by key.
#[test]
fn grid_equals_brute_force() {
    let mut s = 42u64;
    let n = 600;
    let l = 0.5;
    let x: Vec<f64> = (0..n).map(|_| l * lcg(&mut s)).collect();
    let y: Vec<f64> = (0..n).map(|_| l * lcg(&mut s)).collect();
    let r: Vec<f64> = (0..n).map(|_| 0.004 + 0.004 * lcg(&mut s)).collect();
    let skin = 0.002;
    let h = [[l, 0.1 * l], [0.02 * l, 0.95 * l]];
    for dom in [Domain::Open, Domain::Periodic { h }] {
        let got = build(&x, &y, &r, skin, dom, &PairList::default());
        let det = h[0][0] * h[1][1] - h[0][1] * h[1][0];
        let hi = [[h[1][1] / det, -h[0][1] / det], [-h[1][0] / det, h[0][0] / det]];
        let mut want = Vec::new();
        for i in 0..n {
            for j in i + 1..n {
                let (mut dx, mut dy) = (x[j] - x[i], y[j] - y[i]);
                if let Domain::Periodic { .. } = dom {
                    let s1 = hi[0][0].mul_add(dx, hi[0][1] * dy);
                    let s2 = hi[1][0].mul_add(dx, hi[1][1] * dy);
                    let (k1, k2) = (-s1.round(), -s2.round());
                    dx += h[0][0].mul_add(k1, h[0][1] * k2);
                    dy += h[1][0].mul_add(k1, h[1][1] * k2);
                }
                let c = r[i] + r[j] + skin;
                if dx.mul_add(dx, dy * dy) < c * c {
                    want.push((i as u32, j as u32));
                }
            }
        }
        let pairs: Vec<(u32, u32)> = got.i.iter().copied().zip(got.j.iter().copied()).collect();
        assert_eq!(pairs, want, "{dom:?}");
        assert!(!pairs.is_empty());
        // Histories follow their pair through a rebuild.
        let mut old = got.clone();
        for k in 0..old.len() {
            old.fs[k] = (old.i[k] * 1000 + old.j[k]) as f64;
        }
        let again = build(&x, &y, &r, skin, dom, &old);
        for k in 0..again.len() {
            assert_eq!(again.fs[k], (again.i[k] * 1000 + again.j[k]) as f64);
        }
    }
}
