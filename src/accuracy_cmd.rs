//! `whirlmap accuracy`: the work-precision study (cases x settings x tolerances against a
//! DOP853 reference), written as CSV, Markdown and log-log charts.
//!
//! Exit codes: 0 done (failed ladder runs are rows, not errors); 2 bad case file; 3 a
//! reference run failed; 4 an output could not be written.

use crate::Failure;
use anyhow::Context;
use std::path::PathBuf;
use whirlmap_plot::accuracy::{draw_work_precision, CostAxis, RunCost, StudyRun};
use whirlmap_sweep::accuracy::{run, to_csv, to_markdown, AccuracySpec, AccuracySpecError, Study};

/// Arguments of `whirlmap accuracy`.
#[derive(clap::Args)]
pub struct AccuracyArgs {
    /// Case file (JSON): cases, tolerance ladder, settings.
    #[arg(long, default_value = "sweeps/accuracy-cases.json")]
    cases: PathBuf,
    /// Output folder. A folder that already holds results (the committed `results/accuracy`
    /// among them) is refused without --overwrite.
    #[arg(long, default_value = "results/accuracy")]
    out: PathBuf,
    /// Replace the results already in the output folder.
    #[arg(long)]
    overwrite: bool,
    /// Worker threads (1 gives the cleanest wall times); default 1.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=4096))]
    threads: u32,
}

/// Runs the study and writes `accuracy.csv`, `accuracy.md`, `study.json` and the charts.
pub fn run_cmd(a: &AccuracyArgs) -> Result<(), Failure> {
    // The error's text already carries its cause: `coded` keeps it from being printed twice
    // (as the error and again as its source).
    let spec = AccuracySpec::load(&a.cases).map_err(|e| Failure::coded(2, e))?;
    crate::refuse_existing_results(&a.out, a.overwrite).map_err(Failure::Input)?;
    std::fs::create_dir_all(&a.out)
        .with_context(|| format!("cannot create {}", a.out.display()))
        .map_err(Failure::Output)?;
    let pool = whirlmap_sweep::pool::pool(Some(a.threads as usize))
        .map_err(|e| Failure::Input(e.into()))?;
    let jobs = spec.cases.len()
        * (2 + 3
            + spec
                .settings
                .iter()
                .map(|s| s.rtol.as_ref().unwrap_or(&spec.rtol).len())
                .sum::<usize>());
    errln!(
        "whirlmap accuracy: {} cases, {} settings, {jobs} drops on {} thread(s)",
        spec.cases.len(),
        spec.settings.len(),
        a.threads
    );
    let study = pool.install(|| run(&spec)).map_err(|e| match e {
        AccuracySpecError::Range { ref field, .. } if field == "cases" => Failure::coded(3, e),
        e => Failure::coded(2, e),
    })?;
    let write = |name: &str, text: String| {
        let p = a.out.join(name);
        std::fs::write(&p, text)
            .with_context(|| format!("cannot write {}", p.display()))
            .map_err(Failure::Output)
    };
    write("accuracy.csv", to_csv(&study))?;
    let md = to_markdown(&study, &spec);
    write("accuracy.md", md.clone())?;
    write(
        "study.json",
        serde_json::to_string_pretty(&study).expect("a study serialises"),
    )?;
    let (cases, runs) = chart_runs(&study);
    for (axis, stem) in [
        (CostAxis::RhsEvals, "work_precision"),
        (CostAxis::WallMs, "work_precision_wall"),
    ] {
        for ext in ["png", "svg"] {
            let p = a.out.join(format!("{stem}.{ext}"));
            let title = format!("Work-precision: {} (reference DOP853)", spec.name);
            draw_work_precision(&p, &cases, &runs, axis, &title)
                .map_err(|e| Failure::Output(e.into()))?;
        }
    }
    outln!("{md}");
    errln!("written to {}", a.out.display());
    Ok(())
}

/// The study as the work-precision chart takes it: the cases in order, and every run reduced
/// to its cost and worst relative error.
fn chart_runs(study: &Study) -> (Vec<String>, Vec<StudyRun>) {
    let cases = study.references.iter().map(|r| r.case.clone()).collect();
    let runs = study
        .rows
        .iter()
        .map(|r| StudyRun {
            case: r.case.clone(),
            setting: r.setting.clone(),
            rtol: r.rtol,
            cost: r.result.as_ref().ok().map(|(m, e)| RunCost {
                rhs_evals: m.rhs_evals,
                wall_ms: m.wall_ms,
                worst_rel: e.worst_rel(),
                class_agrees: e.class_agrees,
            }),
        })
        .collect();
    (cases, runs)
}
