//! Cost of one Newton iteration (material evaluation, assembly of residual and tangent,
//! numeric Cholesky factorization with a reused symbolic analysis, solve) on Q8 meshes of
//! the unit panel with the elastic Cosserat material. Prints ms per iteration.
//!
//! Run: `cargo bench -p cosdem-study --bench newton_iteration`.

use cosdem_fem::solve::IterationTiming;
use std::time::Instant;

fn main() {
    let args: Vec<usize> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
    let sizes = if args.is_empty() { vec![10, 50, 200] } else { args };
    for n in sizes {
        let t = Instant::now();
        let (mut solver, mut mat) = cosdem_study::bench::fe_panel(n).unwrap();
        let setup = t.elapsed().as_secs_f64() * 1e3;
        let first = solver.iteration_work(&mut mat).unwrap(); // includes the symbolic analysis
        let reps = if n >= 200 { 3 } else { 10 };
        let mut sum = IterationTiming::default();
        for _ in 0..reps {
            let t = std::hint::black_box(solver.iteration_work(&mut mat).unwrap());
            sum.material_s += t.material_s / reps as f64;
            sum.assembly_s += t.assembly_s / reps as f64;
            sum.solve_s += t.solve_s / reps as f64;
        }
        let ms = |s: f64| s * 1e3;
        println!(
            "Q8 {n}x{n}: {} free dofs, nnz {}: setup {setup:.1} ms; first iteration {:.1} ms \
             (symbolic analysis included); then per Newton iteration {:.2} ms = material {:.2} + \
             assembly {:.2} + factorization and solve {:.2}",
            solver.dofs().n_free,
            solver.pattern().nnz(),
            ms(first.material_s + first.assembly_s + first.solve_s),
            ms(sum.material_s + sum.assembly_s + sum.solve_s),
            ms(sum.material_s),
            ms(sum.assembly_s),
            ms(sum.solve_s),
        );
    }
}
