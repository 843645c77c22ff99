//! The spec's wire form and its refusals.

use super::*;

/// The JSON of one value of every variant of every part of the spec, and of the default spec.
/// This JSON is what a CreateAssemblies request carries and what checkpoint digests hash.
fn every_variant() -> Vec<String> {
    fn json<T: Serialize>(value: &T) -> String {
        serde_json::to_string(value).unwrap()
    }
    vec![
        json(&AssemblySpec::default()),
        json(&PackingSpec::hexagonal(0.005, 0.1)),
        json(&PackingSpec::Random {
            r_min: 0.004,
            r_max: 0.006,
            radii: vec![0.005, 0.004],
            side: 0.1,
            seed: 7,
            confining_stress: 1e5,
        }),
        json(&NormalModel::Linear { k_n: 6.7e7 }),
        json(&NormalModel::LinearDashpot { k_n: 6.7e7, c_n: 10.0 }),
        json(&TangentialModel::None),
        json(&TangentialModel::Coulomb { k_s: 3.4e7, mu_s: 0.5, c_s: 0.25 }),
        json(&RollingModel::None),
        json(&RollingModel::Coulomb { k_r: 25.0, mu_r: 0.2, c_r: 0.125 }),
        json(&BoundarySpec::Penalty { eps_f: 6.7e6, eps_c: 1e3 }),
        json(&BoundarySpec::Periodic),
        json(&Driver::default()),
        json(&Driver::fire()),
        json(&Criterion::UnbalancedForce),
        json(&Criterion::KineticEnergy),
        json(&TangentKind::Paper),
        json(&TangentKind::SlidingAware),
        json(&TangentKind::Secant),
        json(&TangentKind::Perturbation { strain: 1e-5 }),
        json(&TangentKind::Adaptive { sliding: 0.3, strain: 1e-5 }),
    ]
}

/// The JSON recorded before the variants without settings were made to refuse extra keys
/// (`deserialize_with = "no_settings"`, which changes reading only): writing must not change, byte
/// for byte, since workers read it and checkpoint digests hash it.
const RECORDED: [&str; 20] = [
    r#"{"packing":{"kind":"hexagonal","radius":0.005,"side":0.1},"contact":{"normal":{"model":"linear","k_n":67000000.0},"tangential":{"model":"coulomb","k_s":34000000.0,"mu_s":0.5,"c_s":0.0},"rolling":{"model":"coulomb","k_r":25.0,"mu_r":0.2,"c_r":0.0}},"density":2650.0,"boundary":{"kind":"penalty","eps_f":6700000.0,"eps_c":1000.0},"relaxation":{"driver":{"kind":"cundall","alpha":0.7},"criterion":"unbalanced_force","tolerance":0.0001,"max_steps":400000,"check_every":10,"safety":0.8,"density_scale":1.0,"skin":0.5,"skip_below":0.0,"elastic_shortcut":false,"substep":0.0},"tangent":{"kind":"paper"},"warm_start":false}"#,
    r#"{"kind":"hexagonal","radius":0.005,"side":0.1}"#,
    r#"{"kind":"random","r_min":0.004,"r_max":0.006,"radii":[0.005,0.004],"side":0.1,"seed":7,"confining_stress":100000.0}"#,
    r#"{"model":"linear","k_n":67000000.0}"#,
    r#"{"model":"linear_dashpot","k_n":67000000.0,"c_n":10.0}"#,
    r#"{"model":"none"}"#,
    r#"{"model":"coulomb","k_s":34000000.0,"mu_s":0.5,"c_s":0.25}"#,
    r#"{"model":"none"}"#,
    r#"{"model":"coulomb","k_r":25.0,"mu_r":0.2,"c_r":0.125}"#,
    r#"{"kind":"penalty","eps_f":6700000.0,"eps_c":1000.0}"#,
    r#"{"kind":"periodic"}"#,
    r#"{"kind":"cundall","alpha":0.7}"#,
    r#"{"kind":"fire","alpha_start":0.1,"f_inc":1.1,"f_dec":0.5,"f_alpha":0.99,"n_min":5,"dt_max":1.8}"#,
    r#""unbalanced_force""#,
    r#""kinetic_energy""#,
    r#"{"kind":"paper"}"#,
    r#"{"kind":"sliding_aware"}"#,
    r#"{"kind":"secant"}"#,
    r#"{"kind":"perturbation","strain":0.00001}"#,
    r#"{"kind":"adaptive","sliding":0.3,"strain":0.00001}"#,
];

/// Every variant writes the JSON it wrote before, and reads back to itself.
#[test]
fn every_variant_writes_the_recorded_json() {
    let written = every_variant();
    assert_eq!(written.len(), RECORDED.len());
    for (json, recorded) in written.iter().zip(RECORDED) {
        assert_eq!(json, recorded);
    }
    let spec: AssemblySpec = serde_json::from_str(RECORDED[0]).unwrap();
    assert_eq!(spec, AssemblySpec::default());
}

/// The variants without settings read their tag alone, and refuse any other key by its name:
/// `{ kind = "periodic", eps_f = 1.0 }` is a mistake to report, not a periodic boundary. (A
/// job file's TOML reaches the same `Deserialize` through serde's buffered content, as JSON
/// does; `cosdem-job`'s reference test reads these variants from TOML.)
#[test]
fn a_variant_without_settings_refuses_an_extra_key_by_name() {
    fn check<T: serde::de::DeserializeOwned + PartialEq + std::fmt::Debug>(
        tag: &str,
        name: &str,
        expected: T,
    ) {
        let alone: T = serde_json::from_str(&format!(r#"{{"{tag}": "{name}"}}"#)).unwrap();
        assert_eq!(alone, expected);
        let json = format!(r#"{{"{tag}": "{name}", "eps_f": 1.0}}"#);
        let err = serde_json::from_str::<T>(&json).unwrap_err().to_string();
        assert!(err.contains("unknown field `eps_f`"), "{name}: {err}");
    }
    check("kind", "periodic", BoundarySpec::Periodic);
    check("kind", "paper", TangentKind::Paper);
    check("kind", "sliding_aware", TangentKind::SlidingAware);
    check("kind", "secant", TangentKind::Secant);
    check("model", "none", TangentialModel::None);
    check("model", "none", RollingModel::None);
}

/// `frame`: absent or `reference` reads as [`TangentFrame::Reference`], which is not written
/// (the default spec keeps its recorded JSON above, so digests of existing jobs do not
/// change); `current` is written after `tangent` and reads back; a misspelt frame is refused
/// naming both values.
#[test]
fn the_frame_is_written_only_when_current() {
    let current = AssemblySpec { frame: TangentFrame::Current, ..AssemblySpec::default() };
    let json = serde_json::to_string(&current).unwrap();
    let want = RECORDED[0].replace(
        r#""tangent":{"kind":"paper"},"#,
        r#""tangent":{"kind":"paper"},"frame":"current","#,
    );
    assert_eq!(json, want);
    assert_eq!(serde_json::from_str::<AssemblySpec>(&json).unwrap(), current);
    let reference = serde_json::from_str::<AssemblySpec>(r#"{"frame": "reference"}"#).unwrap();
    assert_eq!(reference, AssemblySpec::default());
    assert_eq!(serde_json::to_string(&reference).unwrap(), RECORDED[0]);
    let err = serde_json::from_str::<AssemblySpec>(r#"{"frame": "curent"}"#).unwrap_err();
    let err = err.to_string();
    assert!(err.contains("curent") && err.contains("`current`"), "{err}");
}
