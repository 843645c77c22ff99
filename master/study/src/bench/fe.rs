//! Figure 3: the FE cost of one Newton iteration against the DEM cost of the same iteration.

use super::{BenchResult, Spread, hexagonal_spec, run_direct};
use cosdem_fem::assembly::{Component, Field};
use cosdem_fem::element::{ElementKind, QuadratureRule};
use cosdem_fem::material::ElasticCosserat;
use cosdem_fem::mesh::Mesh;
use cosdem_fem::solve::{Dirichlet, IterationTiming, Loading, Model, Solver, SolverSettings};
use std::io::Write;

/// The FE benchmark scene: the unit panel meshed `n x n` with Q8 and 2x2 Gauss points, rough
/// platens, top moved down by 1 cm, and its elastic Cosserat material (G = 1e7 Pa, nu = 0.3,
/// Gc = 5e6 Pa, lc = 0.01 m). Shared by `fe_iteration` and `benches/newton_iteration.rs`.
pub fn fe_panel(n: usize) -> cosdem_fem::Result<(Solver, ElasticCosserat)> {
    let mesh = Mesh::rectangle(ElementKind::Q8, 1.0, 1.0, n, n, [0.0, 0.0])?;
    let loading = Loading {
        dirichlet: vec![
            Dirichlet::new("bottom", Component::Ux, 0.0),
            Dirichlet::new("bottom", Component::Uy, 0.0),
            Dirichlet::new("top", Component::Ux, 0.0),
            Dirichlet::new("top", Component::Uy, -0.01),
        ],
        ..Default::default()
    };
    let model = Model {
        mesh,
        field: Field::Cosserat,
        rule: QuadratureRule::Gauss2x2,
        loading,
        kinematics: Default::default(),
    };
    let solver = Solver::new(model, SolverSettings::default())?;
    Ok((solver, ElasticCosserat::new(1e7, 0.3, 5e6, 0.01)))
}

/// The FE cost of one Newton iteration on the `n x n` Q8 panel (2x2 Gauss points, elastic
/// Cosserat material), averaged over `reps` iterations after a first one that includes the
/// symbolic analysis. Returns (free dofs, Gauss points, seconds per iteration split by part).
pub fn fe_iteration(n: usize, reps: usize) -> BenchResult<(usize, usize, IterationTiming)> {
    let (mut solver, mut mat) = fe_panel(n)?;
    solver.iteration_work(&mut mat)?; // symbolic analysis
    let mut sum = IterationTiming::default();
    let reps = reps.max(1);
    for _ in 0..reps {
        let t = std::hint::black_box(solver.iteration_work(&mut mat)?);
        sum.material_s += t.material_s;
        sum.assembly_s += t.assembly_s;
        sum.solve_s += t.solve_s;
    }
    let per = |s: f64| s / reps as f64;
    let mean = IterationTiming {
        material_s: per(sum.material_s),
        assembly_s: per(sum.assembly_s),
        solve_s: per(sum.solve_s),
    };
    let gauss = solver.gauss().len();
    Ok((solver.dofs().n_free, gauss, mean))
}

/// Figure 3: FE cost of one Newton iteration of the `elements x elements` scene against the
/// DEM cost of the same iteration (Gauss points x direct time per `discs`-disc assembly).
pub fn fe_versus_dem(
    elements: usize,
    discs: usize,
    iterations: u64,
    repeats: usize,
    out: &mut dyn Write,
) -> BenchResult<()> {
    let spec = hexagonal_spec(discs);
    let (mut fe, mut dem, mut ratio) = (Vec::new(), Vec::new(), Vec::new());
    let mut parts: [Vec<f64>; 3] = Default::default();
    let (mut dofs, mut gauss, mut n_discs) = (0, 0, 0);
    for rep in 0..repeats {
        let (d, g, t) = fe_iteration(elements, 20)?;
        (dofs, gauss) = (d, g);
        let f = t.material_s + t.assembly_s + t.solve_s;
        for (p, s) in parts.iter_mut().zip([t.material_s, t.assembly_s, t.solve_s]) {
            p.push(s);
        }
        let (run, n) = run_direct(&spec, 8, iterations)?;
        n_discs = n;
        let dem_iteration = g as f64 * run.per_solve();
        writeln!(
            out,
            "  rep {}: FE {:.3} ms, DEM {:.3} ms per point x {g} = {:.1} ms, FE/DEM {:.3}%",
            rep + 1,
            f * 1e3,
            run.per_solve() * 1e3,
            dem_iteration * 1e3,
            100.0 * f / dem_iteration
        )?;
        fe.push(f);
        dem.push(dem_iteration);
        ratio.push(f / dem_iteration);
    }
    writeln!(
        out,
        "FE versus DEM per Newton iteration, Q8 {elements}x{elements} ({dofs} free dofs, {gauss} \
         Gauss points of {n_discs} discs, DEM on one core), median [min .. max]:"
    )?;
    writeln!(
        out,
        "  FE (material + assembly + factorization + solve): {} ms",
        Spread::of(&fe).show(1e3, 3)
    )?;
    for (name, p) in [
        "material (kinematics, stress, tangent)",
        "assembly (residual, tangent)",
        "factorization + solve",
    ]
    .iter()
    .zip(&parts)
    {
        writeln!(out, "    {name:<38}: {} ms", Spread::of(p).show(1e3, 3))?;
    }
    writeln!(
        out,
        "  DEM ({gauss} x direct solve)                      : {} ms",
        Spread::of(&dem).show(1e3, 1)
    )?;
    writeln!(
        out,
        "  FE / DEM                                         : {} %",
        Spread::of(&ratio).show(100.0, 3)
    )?;
    Ok(())
}
