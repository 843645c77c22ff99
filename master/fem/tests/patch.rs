//! Patch tests: a linear displacement field with its continuum rotation (constant strain),
//! and linear displacement and micro-rotation fields with `Gc = 0` (constant strain and
//! curvature), prescribed on the boundary of a distorted 3x3 patch, are reproduced at every
//! interior node and Gauss point to round-off, for Q8 (2x2 reduced), Q9 (3x3), the 6-node
//! triangle with its 3-point (reduced) and 6-point (full) rules, and meshes mixing Q8 or Q9
//! with triangles (each family on its rule of that role). The largest errors are printed
//! (`--nocapture`).
//!
//! Why `Gc = 0` for constant curvature: a linear `w` makes `e_xy - e_yx = u_y,x - u_x,y - 2w`
//! linear, so with `Gc > 0` the skew stress `s_xy - s_yx = 2 Gc (e_xy - e_yx)` varies and the
//! moment balance needs a body couple; with `Gc = 0` the stresses are constant and the patch
//! is in equilibrium without loads. Tolerance: 1e-10 relative to the field magnitude (the
//! solve of a well-conditioned ~150-dof system loses a few digits of 1e-16).

mod common;

use common::{
    ELEMENTS, MIXED, TRIANGLES, boundary_values, distorted_mixed_square, distorted_square,
};
use cosdem_fem::assembly::Field;
use cosdem_fem::material::ElasticCosserat;
use cosdem_fem::solve::{Model, Solver, SolverSettings};

fn patch(field: Field, material: ElasticCosserat, exact: fn([f64; 2]) -> [f64; 3]) {
    let uniform = ELEMENTS.into_iter().chain(TRIANGLES).map(|(k, r)| (k, distorted_square(k), r));
    let mixed = MIXED.into_iter().map(|(k, r)| (k, distorted_mixed_square(k), r));
    for (kind, mesh, rule) in uniform.chain(mixed) {
        let kind = if mesh.uniform_kind().is_some() {
            format!("{kind:?}")
        } else {
            format!("{kind:?}+T6")
        };
        let loading = boundary_values(&mesh, field, exact);
        let model = Model { mesh, field, rule, loading, kinematics: Default::default() };
        let settings = SolverSettings { steps: 1, ..Default::default() };
        let mut solver = Solver::new(model, settings).unwrap();
        let mut mat = material;
        solver.run(&mut mat, &mut ()).unwrap();
        let view = solver.solution();
        let ndf = field.ndf();
        let scale = 1e-3;
        let (mut worst_node, mut worst_strain) = (0.0f64, 0.0f64);
        for (n, p) in view.mesh.nodes.iter().enumerate() {
            let ex = exact(*p);
            for c in 0..ndf {
                let err = (view.dofs[n * ndf + c] - ex[c]).abs();
                worst_node = worst_node.max(err);
                assert!(err < 1e-10 * scale, "{kind} {field:?} node {n} comp {c}: error {err:e}");
            }
        }
        let s0 = view.gauss_points[0].stress;
        let smax = s0.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for g in view.gauss_points {
            for k in 0..6 {
                let e = exact_strain(field, exact, g.position);
                worst_strain = worst_strain.max((g.strain[k] - e[k]).abs());
                assert!(
                    (g.strain[k] - e[k]).abs() < 1e-10 * scale,
                    "{kind} strain {k} at {}",
                    g.id
                );
                assert!(
                    (g.stress[k] - s0[k]).abs() < 1e-10 * smax,
                    "{kind} stress {k} at {}",
                    g.id
                );
            }
        }
        println!(
            "{kind} {rule:?} {field:?}: largest nodal error {worst_node:.2e}, strain error \
             {worst_strain:.2e} (field scale {scale:e})"
        );
    }
}

/// Strain of a linear exact field at `p` (differences over a unit step are exact for linear
/// functions). The Cauchy field's `w` is the continuum rotation.
fn exact_strain(field: Field, exact: fn([f64; 2]) -> [f64; 3], p: [f64; 2]) -> [f64; 6] {
    let f = exact(p);
    let dx = exact([p[0] + 1.0, p[1]]);
    let dy = exact([p[0], p[1] + 1.0]);
    let d = |c: usize| [dx[c] - f[c], dy[c] - f[c]];
    let (gx, gy, gw) = (d(0), d(1), d(2));
    let w = match field {
        Field::Cosserat => f[2],
        Field::Cauchy => 0.5 * (gy[0] - gx[1]),
    };
    let k = if field == Field::Cosserat { gw } else { [0.0; 2] };
    [gx[0], gy[1], gy[0] - w, gx[1] + w, k[0], k[1]]
}

/// u_x = 1e-3 (1 + 2x - 3y), u_y = 1e-3 (-1 + 0.5x + 1.5y), w = continuum rotation
/// (u_y,x - u_x,y)/2 = 1e-3 * 1.75.
fn constant_strain(p: [f64; 2]) -> [f64; 3] {
    let [x, y] = p;
    [1e-3 * (1.0 + 2.0 * x - 3.0 * y), 1e-3 * (-1.0 + 0.5 * x + 1.5 * y), 1e-3 * 1.75]
}

/// Same displacements, w = 1e-3 (0.5 + 2x - y): constant curvature (2e-3, -1e-3).
fn constant_curvature(p: [f64; 2]) -> [f64; 3] {
    let [x, y] = p;
    let u = constant_strain(p);
    [u[0], u[1], 1e-3 * (0.5 + 2.0 * x - y)]
}

#[test]
fn constant_strain_patch_cosserat() {
    patch(Field::Cosserat, ElasticCosserat::new(1e6, 0.3, 4e5, 0.1), constant_strain);
}

#[test]
fn constant_curvature_patch_cosserat_gc_zero() {
    patch(Field::Cosserat, ElasticCosserat::new(1e6, 0.3, 0.0, 0.1), constant_curvature);
}

#[test]
fn constant_strain_patch_cauchy() {
    patch(Field::Cauchy, ElasticCosserat::new(1e6, 0.3, 4e5, 0.1), constant_strain);
}
