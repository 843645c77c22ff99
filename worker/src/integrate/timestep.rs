use crate::contact::Law;

/// Critical step `2 / omega_max` of the disc system, `omega_max` from a Gershgorin bound on
/// the mass-normalized stiffness of the smallest disc (mass `m`, inertia `i`, radius `r`)
/// with six contacts to equally small discs, plus its penalty springs `kf` (N/m) and `kc`
/// (N m/rad). Per contact and in mass-normalized units, the rows are: normal `2 k_n / m`;
/// tangential `(2 + 2 sqrt 2) k_s / m` (self, partner, and the two lever couplings
/// `k_s r / sqrt(m I)`); rotation `(2 k_s r^2 + 2 k_r) / I + 2 sqrt 2 k_s / m`.
pub fn critical_step(law: &Law, m: f64, i: f64, r: f64, kf: f64, kc: f64) -> f64 {
    const Z: f64 = 6.0;
    let s2 = std::f64::consts::SQRT_2;
    let normal = 2.0 * law.kn / m;
    let tang = (2.0 + 2.0 * s2) * law.ks / m;
    let rot = (2.0 * law.ks * r * r + 2.0 * law.kr) / i + 2.0 * s2 * law.ks / m;
    let w2 = Z * normal.max(tang).max(rot) + kf / m + kc / i;
    2.0 / w2.sqrt()
}
