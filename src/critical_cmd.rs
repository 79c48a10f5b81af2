//! `whirlmap critical`: the critical backward-whirl speed for each friction coefficient.
//!
//! Exit codes as the rest of the tool: 2 for bad input (validated before any drop runs).
//! Failed drops do not fail the command: they are reported in each result.

use crate::{build_scene, Failure};
use serde::Serialize;
use std::path::PathBuf;
use std::time::Instant;
use whirlmap_core::{InvalidParameter, MODEL_VERSION};
use whirlmap_sweep::classify::{ClassifyParams, OrbitClass};
use whirlmap_sweep::critical::{
    check_mus, critical_speeds_with, CriticalOptions, CriticalResult, DEFAULT_SCAN_POINTS,
};
use whirlmap_sweep::recheck::{recheck_bracket, Recheck};

#[derive(clap::Args)]
pub struct CriticalArgs {
    /// Friction coefficients to search, comma-separated, each in [0, 2] (e.g. 0.3,0.35,0.4).
    #[arg(
        long,
        value_delimiter = ',',
        required = true,
        allow_negative_numbers = true
    )]
    mu: Vec<f64>,
    /// Lowest release speed searched (r/min), >= 0.
    #[arg(long, allow_negative_numbers = true)]
    from: f64,
    /// Highest release speed searched (r/min), > --from.
    #[arg(long, allow_negative_numbers = true)]
    to: f64,
    /// Stop bisecting when the bracket is this narrow (r/min), > 0.
    #[arg(long, default_value_t = 50.0, allow_negative_numbers = true)]
    tol_rpm: f64,
    /// Points of the coarse scan over [--from, --to], >= 2.
    #[arg(long, default_value_t = DEFAULT_SCAN_POINTS)]
    scan_points: usize,
    /// Simulated time of each drop (s).
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    duration_s: f64,
    /// Scene file (JSON); any subset of the fields printed by `whirlmap scene`.
    #[arg(long)]
    scene: Option<PathBuf>,
    /// Override one scene parameter, e.g. `--set clearance_m=2e-4`.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
    /// Print the results as JSON instead of tables.
    #[arg(long)]
    json: bool,
    /// Fidelity preset (draft, standard, reference) for the search; the two bracket cells
    /// are then re-checked at the next tighter preset (recorded as `recheck`).
    #[arg(long)]
    fidelity: Option<whirlmap_core::Fidelity>,
}

/// The JSON output: the search settings and one result per mu.
#[derive(Serialize)]
struct Output<'a> {
    from_rpm: f64,
    to_rpm: f64,
    tol_rpm: f64,
    scan_points: usize,
    duration_s: f64,
    scene_hash: String,
    model_version: u32,
    results: Vec<MuResult<'a>>,
}

#[derive(Serialize)]
struct MuResult<'a> {
    mu: f64,
    #[serde(flatten)]
    result: &'a CriticalResult,
    #[serde(skip_serializing_if = "Option::is_none")]
    recheck: Option<Recheck>,
}

/// Names a bad flag: `--from = -5: allowed ...`.
fn flag_error(e: InvalidParameter) -> Failure {
    let flag = match e.field.as_str() {
        "from_rpm" => "--from",
        "to_rpm" => "--to",
        "tol_rpm" => "--tol-rpm",
        "scan_points" => "--scan-points",
        "duration_s" => "--duration-s",
        "mu" => "--mu",
        other => other,
    };
    Failure::Input(anyhow::anyhow!(
        "invalid {flag} = {}: allowed {}",
        e.value,
        e.allowed
    ))
}

pub fn run(a: &CriticalArgs) -> Result<(), Failure> {
    let opts = CriticalOptions {
        from_rpm: a.from,
        to_rpm: a.to,
        tol_rpm: a.tol_rpm,
        scan_points: a.scan_points,
        duration_s: a.duration_s,
        classify: ClassifyParams::default(),
    };
    opts.validate().map_err(flag_error)?;
    check_mus(&a.mu).map_err(flag_error)?;
    let mut base = build_scene(a.scene.as_deref(), &a.set, None, None).map_err(Failure::Input)?;
    if let Some(f) = a.fidelity {
        f.apply(&mut base);
    }
    // Each mu must make a valid scene (e.g. mu_static >= mu_dynamic) before anything runs.
    for &mu in &a.mu {
        let mut s = base.clone();
        s.mu_dynamic = mu;
        s.validate()
            .map_err(|e| Failure::Input(anyhow::anyhow!("with --mu {mu}: {e}")))?;
    }

    let start = Instant::now();
    let results = critical_speeds_with(&base, &a.mu, &opts);
    let drop_opts = whirlmap_core::DropOptions {
        duration_s: a.duration_s,
        ..Default::default()
    };
    let rechecks: Vec<Option<Recheck>> = results
        .iter()
        .map(|(mu, r)| {
            let tighter = a.fidelity.and_then(|f| f.tighter())?;
            let mut s = base.clone();
            s.mu_dynamic = *mu;
            recheck_bracket(&s, r, tighter, &drop_opts, &ClassifyParams::default())
        })
        .collect();
    let wall_s = start.elapsed().as_secs_f64();

    if a.json {
        let out = Output {
            from_rpm: a.from,
            to_rpm: a.to,
            tol_rpm: a.tol_rpm,
            scan_points: a.scan_points,
            duration_s: a.duration_s,
            scene_hash: base.hash_hex(),
            model_version: MODEL_VERSION,
            results: results
                .iter()
                .zip(&rechecks)
                .map(|((mu, result), recheck)| MuResult {
                    mu: *mu,
                    result,
                    recheck: recheck.clone(),
                })
                .collect(),
        };
        println!(
            "{}",
            serde_json::to_string_pretty(&out).expect("results serialise")
        );
        return Ok(());
    }

    println!(
        "whirlmap critical: {}-{} r/min, {} scan points, tolerance {} r/min, {} s per drop",
        a.from, a.to, a.scan_points, a.tol_rpm, a.duration_s
    );
    let class = |c: Option<OrbitClass>| c.map_or("-", |c| c.name());
    for ((mu, r), recheck) in results.iter().zip(&rechecks) {
        println!();
        println!("  mu_d = {mu}");
        match r.bracket {
            Some((lo, hi)) => println!(
                "    bracket (r/min)     {lo:.1} .. {hi:.1}  (width {:.1}{})",
                hi - lo,
                if r.converged { "" } else { ", NOT converged" }
            ),
            None => println!("    bracket (r/min)     none"),
        }
        println!("    class below         {}", class(r.class_lo));
        println!("    class above         {}", class(r.class_hi));
        println!("    drops used          {}", r.drops_used);
        println!(
            "    failed drops        {}",
            if r.failures.is_empty() {
                "0".to_string()
            } else {
                r.failures
                    .iter()
                    .map(|f| format!("{:.1} r/min ({})", f.speed_rpm, f.error))
                    .collect::<Vec<_>>()
                    .join("; ")
            }
        );
        println!(
            "    non-monotone        {}",
            if r.non_monotone { "YES" } else { "no" }
        );
        println!("    note                {}", r.note);
        if let Some(rc) = recheck {
            let show = |o: &whirlmap_sweep::critical::Outcome| match o {
                whirlmap_sweep::critical::Outcome::Class(c) => c.name().to_string(),
                whirlmap_sweep::critical::Outcome::Failed(e) => format!("failed ({e})"),
            };
            println!(
                "    recheck ({})   {:.1}: {}, {:.1}: {} -> {}",
                rc.fidelity,
                rc.lo.0,
                show(&rc.lo.1),
                rc.hi.0,
                show(&rc.hi.1),
                if rc.confirmed {
                    "bracket confirmed"
                } else {
                    "NOT confirmed"
                }
            );
        }
    }
    let drops: usize = results.iter().map(|(_, r)| r.drops_used).sum::<usize>()
        + 2 * rechecks.iter().flatten().count();
    println!();
    println!("  {drops} drops, {wall_s:.2} s wall");
    Ok(())
}
