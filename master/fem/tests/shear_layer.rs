//! Elastic Cosserat shear layer: a strip 0 <= y <= h, unbounded in x, between two rough
//! plates that also stop the micro-rotation: u_x(0) = 0, u_x(h) = U, w(0) = w(h) = 0, u_y = 0.
//!
//! Derivation. Look for u_x = u(y), u_y = 0, w = w(y). Then e_xx = e_yy = k_x = 0,
//! e_xy = -w, e_yx = u' + w, k_y = w', and Eq. 8 gives
//!   s_yx = (G+Gc) u' + 2 Gc w,   s_xy = (G-Gc) u' - 2 Gc w,   m_y = B w',  B = 2 G lc^2.
//! Equilibrium: s_yx,y = 0, so s_yx = tau (a constant, the shear stress on the plates);
//! moment balance m_y,y + s_xy - s_yx = 0 gives B w'' - 2 Gc u' - 4 Gc w = 0. Eliminating
//! u' = (tau - 2 Gc w) / (G+Gc):
//!   w'' - a^2 w = 2 Gc tau / ((G+Gc) B),     a^2 = 4 G Gc / ((G+Gc) B) = 2 Gc / ((G+Gc) lc^2).
//! With w(0) = w(h) = 0:
//!   w(y) = -tau/(2G) [1 - cosh(a (y - h/2)) / cosh(a h/2)]
//! (the interior value -tau/(2G) = -u'/2 is the continuum rotation: no relative rotation
//! away from the plates; boundary layers of width 1/a ~ lc at the plates). Integrating u':
//!   u(y) = tau y / G - Gc tau / (G (G+Gc)) [sinh(a (y - h/2)) + sinh(a h/2)] / (a cosh(a h/2)),
//! and u(h) = U fixes
//!   tau = G U / (h - 2 Gc tanh(a h/2) / (a (G+Gc))).
//! Limits: Gc -> 0 or lc -> 0 (a -> infinity, tanh/a -> 0) give the classical tau = G U / h,
//! u linear: the Cosserat strip is stiffer, by a boundary-layer term of relative size ~lc/h.
//!
//! FE check: a 0.5 x 1 strip of 2 x 40 elements with u_y = 0 everywhere and the exact
//! u, w prescribed on the left and right sides (the infinite strip cut out of its
//! neighbours). Tolerances: the layer (1/a = 0.061 m) spans 2.5 elements of 0.025 m; quadratic
//! elements resolve exp(-a y) with a nodal error of order (a dy)^3 / 100 ~ 1e-3 at most;
//! measured: u 1.6e-6 of U, w 8.1e-5 of max |w|, s_yx 1.2e-4 of tau; asserted: 5e-4.

use cosdem_fem::assembly::{Component, Field};
use cosdem_fem::element::{ElementKind, QuadratureRule};
use cosdem_fem::material::ElasticCosserat;
use cosdem_fem::mesh::Mesh;
use cosdem_fem::solve::{Dirichlet, Loading, Model, Solver, SolverSettings};

struct Layer {
    g: f64,
    gc: f64,
    lc: f64,
    h: f64,
    u: f64,
}

impl Layer {
    fn a(&self) -> f64 {
        (2.0 * self.gc / ((self.g + self.gc) * self.lc * self.lc)).sqrt()
    }
    fn tau(&self) -> f64 {
        let a = self.a();
        let (g, gc, h) = (self.g, self.gc, self.h);
        g * self.u / (h - 2.0 * gc * (a * h / 2.0).tanh() / (a * (g + gc)))
    }
    fn exact(&self, y: f64) -> (f64, f64) {
        let (a, tau, g, gc, h) = (self.a(), self.tau(), self.g, self.gc, self.h);
        let c = (a * h / 2.0).cosh();
        let w = -tau / (2.0 * g) * (1.0 - (a * (y - h / 2.0)).cosh() / c);
        let u = tau * y / g
            - gc * tau / (g * (g + gc)) * ((a * (y - h / 2.0)).sinh() + (a * h / 2.0).sinh())
                / (a * c);
        (u, w)
    }
}

fn strip(field: Field, layer: &Layer, ny: usize, profile: bool) -> Solver {
    let mesh = Mesh::rectangle(ElementKind::Q8, 0.5, layer.h, 2, ny, [0.0, 0.0]).unwrap();
    let mut loading = Loading {
        dirichlet: vec![
            Dirichlet::new("all", Component::Uy, 0.0),
            Dirichlet::new("bottom", Component::Ux, 0.0),
            Dirichlet::new("top", Component::Ux, layer.u),
        ],
        ..Default::default()
    };
    if field == Field::Cosserat {
        loading.dirichlet.push(Dirichlet::new("bottom", Component::W, 0.0));
        loading.dirichlet.push(Dirichlet::new("top", Component::W, 0.0));
    }
    for side in ["left", "right"] {
        for &n in mesh.node_set(side).unwrap() {
            let y = mesh.nodes[n][1];
            let (u, w) = if profile { layer.exact(y) } else { (layer.u * y / layer.h, 0.0) };
            loading.nodal_dirichlet.push((n, Component::Ux, u));
            if field == Field::Cosserat {
                loading.nodal_dirichlet.push((n, Component::W, w));
            }
        }
    }
    let model = Model {
        mesh,
        field,
        rule: QuadratureRule::Gauss2x2,
        loading,
        kinematics: Default::default(),
    };
    let mut s = Solver::new(model, SolverSettings { steps: 1, ..Default::default() }).unwrap();
    let mut mat = ElasticCosserat::new(layer.g, 0.3, layer.gc, layer.lc);
    s.run(&mut mat, &mut ()).unwrap();
    s
}

#[test]
fn cosserat_shear_layer_matches_the_analytical_boundary_layers() {
    let layer = Layer { g: 1e6, gc: 5e5, lc: 0.05, h: 1.0, u: 0.01 };
    let s = strip(Field::Cosserat, &layer, 40, true);
    let view = s.solution();
    let (mut eu, mut ew, mut wmax) = (0.0f64, 0.0f64, 0.0f64);
    for (n, p) in view.mesh.nodes.iter().enumerate() {
        let (u, w) = layer.exact(p[1]);
        eu = eu.max((view.dofs[3 * n] - u).abs());
        ew = ew.max((view.dofs[3 * n + 2] - w).abs());
        wmax = wmax.max(w.abs());
    }
    let tau = layer.tau();
    let et = view.gauss_points.iter().map(|g| (g.stress[3] - tau).abs()).fold(0.0, f64::max);
    println!(
        "tau = {tau:.6e} (classical {:.6e}); max errors: u {:.2e} of U, w {:.2e} of max w, \
         s_yx {:.2e} of tau",
        layer.g * layer.u / layer.h,
        eu / layer.u,
        ew / wmax,
        et / tau
    );
    assert!(eu < 5e-4 * layer.u);
    assert!(ew < 5e-4 * wmax);
    assert!(et < 5e-4 * tau);
    assert!(tau > layer.g * layer.u / layer.h, "the Cosserat strip is stiffer");
}

/// lc -> 0 and Gc -> 0: the analytical tau tends to G U / h (checked on the formula), and the
/// FE strip with Gc = 0, lc = 1e-6 gives the classical linear profile u = U y / h with
/// tau = G U / h to round-off (1e-9 relative), as does the Cauchy field (for any Gc, since
/// its rotation is the continuum rotation).
#[test]
fn classical_plane_strain_shear_is_recovered() {
    for (gc, lc) in [(1e-6, 0.05), (5e5, 1e-7)] {
        let l = Layer { g: 1e6, gc, lc, h: 1.0, u: 0.01 };
        assert!((l.tau() / (l.g * l.u / l.h) - 1.0).abs() < 1e-5, "gc {gc} lc {lc}");
    }
    let classical = 1e6 * 0.01 / 1.0;
    for (field, gc) in [(Field::Cosserat, 0.0), (Field::Cauchy, 5e5)] {
        let layer = Layer { g: 1e6, gc, lc: 1e-6, h: 1.0, u: 0.01 };
        let s = strip(field, &layer, 4, false);
        let view = s.solution();
        let ndf = field.ndf();
        for (n, p) in view.mesh.nodes.iter().enumerate() {
            assert!((view.dofs[ndf * n] - 0.01 * p[1]).abs() < 1e-9 * 0.01, "{field:?} node {n}");
        }
        for g in view.gauss_points {
            assert!((g.stress[3] / classical - 1.0).abs() < 1e-9, "{field:?}: {:?}", g.stress);
            assert!((g.stress[2] / classical - 1.0).abs() < 1e-9, "{field:?}: {:?}", g.stress);
        }
    }
}
