//! The energy audit residuals of sound drops, the measurement behind
//! `whirlmap_core::drop::AUDIT_THRESHOLD`:
//! `cargo run --release --example audit_residuals`.
//!
//! Runs the full extremes matrix (`whirlmap_sweep::extremes`) plus drops without spin (where
//! the only energy is the small drop energy m g s, so the relative residual is largest) at
//! the scene's tolerance, at rtol 1e-3 and 1e-2 (the loosest a scene allows), and with the
//! draft preset (with and without spin), and prints each residual and the largest per
//! setting (`--quick`: the reduced matrix of the CI test, drops of 10-30 ms). A drop whose
//! audit fails reports its residual from the typed error, so the measurement does not depend
//! on the threshold.

use whirlmap_core::{simulate, DropOptions, Scene, SolveError};
use whirlmap_sweep::extremes::matrix;

/// A named change to every scene of the matrix.
type Setting = (&'static str, fn(&mut Scene));

fn residual(scene: &Scene, duration_s: f64) -> Result<f64, String> {
    let opts = DropOptions {
        duration_s,
        ..Default::default()
    };
    match simulate(scene, &opts) {
        Ok(r) => Ok(r.energy.residual_rel),
        Err(SolveError::EnergyAudit { residual_rel, .. }) => Ok(residual_rel),
        Err(e) => Err(e.kind().to_string()),
    }
}

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    let mut cases: Vec<(String, Scene, f64)> = Vec::new();
    for p in matrix(!quick) {
        if p.duration_s > 1.0 && quick {
            continue;
        }
        cases.push((p.name.clone(), p.scene.clone(), p.duration_s));
    }
    for speed in [0.0, 1.0] {
        for mu in [0.0, 0.3, 2.0] {
            let mut s = Scene::paper();
            s.speed_rpm = speed;
            s.mu_dynamic = mu;
            cases.push((format!("no spin: {speed} r/min, mu {mu}"), s, 0.2));
        }
    }
    let mut worst: Vec<(String, f64, String)> = Vec::new();
    let settings: [Setting; 5] = [
        ("scene's rtol", |_| {}),
        ("rtol 1e-3", |s| s.solver.rtol = 1e-3),
        ("rtol 1e-2", |s| s.solver.rtol = 1e-2),
        ("draft", |s| whirlmap_core::Fidelity::Draft.apply(s)),
        ("draft, no spin", |s| {
            whirlmap_core::Fidelity::Draft.apply(s);
            s.speed_rpm = 0.0;
        }),
    ];
    for (label, set) in settings {
        let mut max = (0.0_f64, String::new());
        for (name, scene, d) in &cases {
            let mut s = scene.clone();
            set(&mut s);
            match residual(&s, *d) {
                Ok(r) => {
                    println!("{label:<14} {name:<50} residual {r:.2e}");
                    if r > max.0 {
                        max = (r, name.clone());
                    }
                }
                Err(kind) => println!("{label:<14} {name:<50} failed: {kind}"),
            }
        }
        worst.push((label.to_string(), max.0, max.1));
    }
    println!();
    for (label, r, name) in worst {
        println!("largest residual at {label}: {r:.2e} ({name})");
    }
}
