//! Manufactured solution of the elastic Cosserat equations (THEORY.md Eqs. 8-10) on the unit
//! square, all boundary dofs clamped:
//!   u_x = 1e-3 sin(pi x) sin(pi y),  u_y = 5e-4 sin(2 pi x) sin(pi y),
//!   w = 2e-3 sin(pi x) sin(2 pi y),
//! with body force F = -(div s) and body couple M = -(div m + s_xy - s_yx) computed from the
//! exact fields. Under h-refinement (2, 4, 8, 16 elements per side) quadratic elements should
//! give L2 displacement error ~ h^3 and energy-norm error ~ h^2, for Q8 with 2x2 reduced
//! integration (the paper's element) and Q9 with 3x3, and for 6-node triangles (each cell
//! split in two) with their 3- and 6-point rules, and for mixed meshes (the left half of the
//! cells Q8 or Q9, the right half triangles, each family on its rule of that role). Errors
//! are integrated with 4x4 Gauss points (triangles: the collapsed 4x4 rule, exact to degree
//! 6). The measured rates (last refinement) are compared with
//! `tests/baselines/convergence.txt` within 0.05 and with theory within 0.25 (rates approach
//! their asymptotic value from above or below by O(h) on such coarse meshes). Regenerate the
//! baseline with `COSDEM_WRITE_BASELINE=1 cargo test -p cosdem-fem --test convergence`.

mod common;

use common::{ELEMENTS, MIXED, TRIANGLES, clamp_all_sides, integrate, mixed_square};
use cosdem_fem::assembly::Field;
use cosdem_fem::material::ElasticCosserat;
use cosdem_fem::mesh::Mesh;
use cosdem_fem::solve::{BodyLoad, Loading, Model, Solver, SolverSettings};
use std::f64::consts::PI;

/// `a sin(p pi x) sin(q pi y)`: value, gradient, Hessian `[xx, xy, yy]`.
fn sinsin(a: f64, p: f64, q: f64, x: [f64; 2]) -> (f64, [f64; 2], [f64; 3]) {
    let (kp, kq) = (p * PI, q * PI);
    let (sx, cx, sy, cy) =
        ((kp * x[0]).sin(), (kp * x[0]).cos(), (kq * x[1]).sin(), (kq * x[1]).cos());
    (
        a * sx * sy,
        [a * kp * cx * sy, a * kq * sx * cy],
        [-a * kp * kp * sx * sy, a * kp * kq * cx * cy, -a * kq * kq * sx * sy],
    )
}

fn fields(x: [f64; 2]) -> [(f64, [f64; 2], [f64; 3]); 3] {
    [sinsin(1e-3, 1.0, 1.0, x), sinsin(5e-4, 2.0, 1.0, x), sinsin(2e-3, 1.0, 2.0, x)]
}

fn exact_strain(x: [f64; 2]) -> [f64; 6] {
    let [(_, gu, _), (_, gv, _), (w, gw, _)] = fields(x);
    [gu[0], gv[1], gv[0] - w, gu[1] + w, gw[0], gw[1]]
}

fn body(m: ElasticCosserat, x: [f64; 2]) -> [f64; 3] {
    let [(_, gu, hu), (_, gv, hv), (w, gw, hw)] = fields(x);
    let (l, g, gc) = (m.lambda, m.shear, m.coupling);
    let b = 2.0 * g * m.length * m.length;
    let sxx_x = (l + 2.0 * g) * hu[0] + l * hv[1];
    let syx_y = (g - gc) * (hv[1] - gw[1]) + (g + gc) * (hu[2] + gw[1]);
    let sxy_x = (g + gc) * (hv[0] - gw[0]) + (g - gc) * (hu[1] + gw[0]);
    let syy_y = l * hu[1] + (l + 2.0 * g) * hv[2];
    let skew = 2.0 * gc * ((gv[0] - w) - (gu[1] + w));
    [-(sxx_x + syx_y), -(sxy_x + syy_y), -(b * (hw[0] + hw[2]) + skew)]
}

struct Errors {
    h: f64,
    l2: f64,
    energy: f64,
}

/// The errors on the `n` x `n` mesh of `kind` (with `mixed`: `kind` in the left half of the
/// cells, triangles in the right).
fn run(
    kind: cosdem_fem::element::ElementKind,
    rule: cosdem_fem::element::QuadratureRule,
    n: usize,
    mixed: bool,
) -> Errors {
    let mat = ElasticCosserat::new(1.0, 0.25, 0.5, 0.2);
    let mesh = if mixed {
        mixed_square(kind, n, n / 2)
    } else {
        Mesh::rectangle(kind, 1.0, 1.0, n, n, [0.0, 0.0]).unwrap()
    };
    let loading = Loading {
        dirichlet: clamp_all_sides(Field::Cosserat),
        body: Some(BodyLoad::new(move |_, x| body(mat, x))),
        ..Default::default()
    };
    let model =
        Model { mesh, field: Field::Cosserat, rule, loading, kinematics: Default::default() };
    let mut solver = Solver::new(model, SolverSettings { steps: 1, ..Default::default() }).unwrap();
    solver.run(&mut mat.clone(), &mut ()).unwrap();
    let view = solver.solution();
    let d = mat.tangent();
    let l2 = integrate(&view, |x, v, _| {
        let f = fields(x);
        (v[0] - f[0].0).powi(2) + (v[1] - f[1].0).powi(2)
    });
    let l2_ref = integrate(&view, |x, _, _| {
        let f = fields(x);
        f[0].0.powi(2) + f[1].0.powi(2)
    });
    let energy_density = |e: [f64; 6]| {
        (0..6).map(|i| (0..6).map(|j| e[i] * d[i][j] * e[j]).sum::<f64>()).sum::<f64>()
    };
    let energy = integrate(&view, |x, v, g| {
        let eh = [g[0][0], g[1][1], g[1][0] - v[2], g[0][1] + v[2], g[2][0], g[2][1]];
        let ex = exact_strain(x);
        energy_density(std::array::from_fn(|k| eh[k] - ex[k]))
    });
    let energy_ref = integrate(&view, |x, _, _| energy_density(exact_strain(x)));
    Errors { h: 1.0 / n as f64, l2: (l2 / l2_ref).sqrt(), energy: (energy / energy_ref).sqrt() }
}

#[test]
fn manufactured_solution_converges_at_optimal_rates() {
    let baseline_path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/baselines/convergence.txt");
    let mut lines = vec![
        "# element rule l2_rate energy_rate (last refinement 8 -> 16 elements per side)"
            .to_string(),
    ];
    let uniform = ELEMENTS.into_iter().chain(TRIANGLES).map(|(k, r)| (k, r, false));
    for (kind, rule, mixed) in uniform.chain(MIXED.into_iter().map(|(k, r)| (k, r, true))) {
        let errs: Vec<Errors> = [2, 4, 8, 16].iter().map(|&n| run(kind, rule, n, mixed)).collect();
        let kind = if mixed { format!("{kind:?}+T6") } else { format!("{kind:?}") };
        let rate = |f: fn(&Errors) -> f64, i: usize| {
            (f(&errs[i]) / f(&errs[i + 1])).ln() / (errs[i].h / errs[i + 1].h).ln()
        };
        for (i, e) in errs.iter().enumerate() {
            let r = if i > 0 {
                format!(
                    "rates l2 {:.3} energy {:.3}",
                    rate(|e| e.l2, i - 1),
                    rate(|e| e.energy, i - 1)
                )
            } else {
                String::new()
            };
            println!(
                "{kind} {rule:?} h = 1/{:<3} L2 {:.3e} energy {:.3e} {r}",
                (1.0 / e.h).round(),
                e.l2,
                e.energy
            );
        }
        let (l2_rate, energy_rate) = (rate(|e| e.l2, 2), rate(|e| e.energy, 2));
        assert!((l2_rate - 3.0).abs() < 0.25, "{kind} L2 rate {l2_rate}");
        assert!((energy_rate - 2.0).abs() < 0.25, "{kind} energy rate {energy_rate}");
        lines.push(format!("{kind} {rule:?} {l2_rate:.4} {energy_rate:.4}"));
    }
    if std::env::var_os("COSDEM_WRITE_BASELINE").is_some() {
        std::fs::write(baseline_path, lines.join("\n") + "\n").unwrap();
        return;
    }
    let baseline = std::fs::read_to_string(baseline_path).unwrap();
    let measured = &lines[1..];
    let stored: Vec<&str> = baseline.lines().filter(|l| !l.starts_with('#')).collect();
    assert_eq!(stored.len(), measured.len(), "baseline rows");
    for (s, m) in stored.iter().zip(measured) {
        let sv: Vec<&str> = s.split_whitespace().collect();
        let mv: Vec<&str> = m.split_whitespace().collect();
        assert_eq!(sv[..2], mv[..2]);
        for k in 2..4 {
            let (a, b): (f64, f64) = (sv[k].parse().unwrap(), mv[k].parse().unwrap());
            assert!((a - b).abs() < 0.05, "baseline {s} vs measured {m}");
        }
    }
}
