//! `whirlmap accuracy`: the work-precision study (cases x settings x tolerances against a
//! DOP853 reference), written as CSV, Markdown and log-log charts.
//!
//! Exit codes: 0 done (failed ladder runs are rows, not errors); 2 bad case file; 3 a
//! reference run failed; 4 an output could not be written.

use crate::Failure;
use anyhow::Context;
use std::path::PathBuf;
use whirlmap_plot::accuracy::{draw_work_precision, CostAxis, RunCost, StudyRun};
use whirlmap_results::files::{
    ACCURACY_CSV_FILE, ACCURACY_REPORT_FILE, STUDY_FILE, WORK_PRECISION_CHARTS,
};
use whirlmap_sweep::accuracy::{run, to_csv, to_markdown, AccuracySpec, AccuracySpecError, Study};

/// Arguments of `whirlmap accuracy`.
#[derive(clap::Args)]
pub struct AccuracyArgs {
    /// Case file (JSON): cases, tolerance ladder, settings. The default is relative to the
    /// repository's top; run elsewhere, give the file's path.
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
    #[arg(long, default_value_t = 1, allow_negative_numbers = true, value_parser = crate::flags::threads)]
    threads: u32,
    /// Run no drops: draw the charts again from the `study.json` already in --out (the study
    /// of --cases), replacing only the charts.
    #[arg(long, conflicts_with = "overwrite")]
    charts_only: bool,
}

/// Runs the study and writes `accuracy.csv`, `accuracy.md`, `study.json` and the charts.
pub fn run_cmd(a: &AccuracyArgs) -> Result<(), Failure> {
    // The error's text already carries its cause: `coded` keeps it from being printed twice
    // (as the error and again as its source).
    let spec = AccuracySpec::load(&a.cases).map_err(|e| Failure::coded(2, e))?;
    if a.charts_only {
        let study = read_study(&a.out, &spec)?;
        draw_charts(&a.out, &spec.name, &study)?;
        errln!(
            "charts drawn again from {} into {}",
            a.out.join(STUDY_FILE).display(),
            a.out.display()
        );
        return Ok(());
    }
    crate::refuse_existing_results(&a.out, a.overwrite).map_err(Failure::Input)?;
    std::fs::create_dir_all(&a.out)
        .with_context(|| format!("cannot create {}", a.out.display()))
        .map_err(Failure::Output)?;
    let storage = |e: whirlmap_sweep::sweep::SweepError| Failure::coded(e.exit_code(), e);
    // One writer at a time: a sweep or another study writing the folder refuses this one
    // (exit 2), and this one holds the folder until it ends.
    let _lock = whirlmap_sweep::folder::FolderLock::acquire(&a.out, "accuracy").map_err(storage)?;
    let previous = if a.overwrite {
        whirlmap_sweep::folder::move_owned_aside(&a.out).map_err(storage)?
    } else {
        None
    };
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
    write(ACCURACY_CSV_FILE, to_csv(&study))?;
    let md = to_markdown(&study, &spec);
    write(ACCURACY_REPORT_FILE, md.clone())?;
    write(
        STUDY_FILE,
        serde_json::to_string_pretty(&study).expect("a study serialises"),
    )?;
    // The study is written: the earlier run's files go (before the charts, so a chart that
    // fails does not leave both).
    whirlmap_sweep::folder::release_previous(previous).map_err(storage)?;
    draw_charts(&a.out, &spec.name, &study)?;
    outln!("{md}");
    errln!("written to {}", a.out.display());
    Ok(())
}

/// The `study.json` in `out`, checked to be a study of `spec`'s cases and settings (exit 2
/// otherwise).
fn read_study(out: &std::path::Path, spec: &AccuracySpec) -> Result<Study, Failure> {
    let path = out.join(STUDY_FILE);
    let text = std::fs::read_to_string(&path)
        .with_context(|| {
            format!(
                "--charts-only draws from {}, which cannot be read: run the study first",
                path.display()
            )
        })
        .map_err(Failure::Input)?;
    let study: Study = serde_json::from_str(&text)
        .with_context(|| format!("{} is not a study's record", path.display()))
        .map_err(Failure::Input)?;
    // The cases in order, and the settings (the preset rows aside) in order of first row.
    let cases: Vec<&str> = study.references.iter().map(|r| r.case.as_str()).collect();
    let mut settings: Vec<&str> = Vec::new();
    for r in &study.rows {
        if !r.setting.starts_with("preset:") && !settings.contains(&r.setting.as_str()) {
            settings.push(&r.setting);
        }
    }
    let want_cases: Vec<&str> = spec.cases.iter().map(|c| c.name.as_str()).collect();
    let want_settings: Vec<&str> = spec.settings.iter().map(|s| s.name.as_str()).collect();
    if (&cases, &settings) != (&want_cases, &want_settings) {
        return Err(Failure::Input(anyhow::anyhow!(
            "{} holds a study of the cases [{}] and settings [{}], not the study of --cases {} \
             (cases [{}], settings [{}])",
            path.display(),
            cases.join(", "),
            settings.join(", "),
            spec.name,
            want_cases.join(", "),
            want_settings.join(", ")
        )));
    }
    Ok(study)
}

/// Draws `work_precision` and `work_precision_wall` (PNG and SVG) of `study` into `out`.
fn draw_charts(out: &std::path::Path, name: &str, study: &Study) -> Result<(), Failure> {
    let (cases, runs) = chart_runs(study);
    for (axis, stem) in [CostAxis::RhsEvals, CostAxis::WallMs]
        .into_iter()
        .zip(WORK_PRECISION_CHARTS)
    {
        for ext in ["png", "svg"] {
            let p = out.join(format!("{stem}.{ext}"));
            let title = format!("Work-precision: {name} (reference DOP853)");
            draw_work_precision(&p, &cases, &runs, axis, &title)
                .map_err(|e| Failure::Output(e.into()))?;
        }
    }
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
