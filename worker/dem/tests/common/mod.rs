//! Helpers shared by the worker's integration tests.
#![allow(dead_code)]

use cosdem_common::MacroDeformation;
use cosdem_dem::{AssemblySpec, BoundarySpec, PackingSpec};

/// Hexagonal spec with radius 5 mm and the given side, paper contact law.
pub fn hex_spec(side: f64, boundary: BoundarySpec) -> AssemblySpec {
    AssemblySpec { packing: PackingSpec::hexagonal(0.005, side), boundary, ..Default::default() }
}

/// Paper penalty boundary.
pub fn penalty() -> BoundarySpec {
    BoundarySpec::Penalty { eps_f: 6.7e6, eps_c: 1.0e3 }
}

/// Deformation from a displacement gradient.
pub fn grad(g: [[f64; 2]; 2]) -> MacroDeformation {
    MacroDeformation::from_gradient(g, 0.0, [0.0; 2])
}

/// Isotropic stretch `(1 + e) I`.
pub fn iso(e: f64) -> MacroDeformation {
    grad([[e, 0.0], [0.0, e]])
}

/// Closed-form hexagonal tangent (THEORY.md) scaled by the contact density factor `rho`
/// (`2 sqrt 3` in the bulk): `(C_xxxx, C_xxyy, C_xyxy, C_xyyx, D)`.
pub fn closed_form(kn: f64, ks: f64, kr: f64, rho: f64) -> [f64; 5] {
    let s = rho / 8.0;
    [s * (3.0 * kn + ks), s * (kn - ks), s * (kn + 3.0 * ks), s * (kn - ks), rho / 2.0 * kr]
}

/// Relative difference `|a - b| / |b|`.
pub fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}
