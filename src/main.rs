//! `whirlmap`: simulate rotor drops onto touchdown bearings.
//!
//! Exit codes: 0 success; 2 bad input (usage, invalid parameter, unreadable scene file,
//! unsupported chart extension); 3 the simulation failed (a typed solver error); 4 an output
//! could not be written.

#[macro_use]
mod output;
mod flags;

use anyhow::Context;
use clap::{Parser, Subcommand};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;
use whirlmap_core::scene::SolverSettings;
use whirlmap_core::{simulate, DropOptions, DropReport, Scene};
use whirlmap_plot::render::{draw_orbit, ImageFormat};
use whirlmap_plot::thermal::draw_temperatures;
use whirlmap_sweep::overrides::apply_assignment;
use whirlmap_sweep::record::DropRecord;

mod accuracy_cmd;
mod bench;
mod compare_cmd;
mod critical_cmd;
mod ensemble_cmd;
mod merge_cmd;
mod render_cmd;
mod shard_cmd;
mod sweep_cmd;

#[derive(Parser)]
#[command(
    name = "whirlmap",
    version = whirlmap_sweep::build_info::DESCRIPTION,
    about = "Rotor drops onto AMB touchdown bearings: orbits, whirl, design charts"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// Refuses to write into `out` when it already holds results (any file but the writers'
/// lock) and `overwrite` is not set, so a command's default folder (`results/...`, which may
/// be committed reference output) is never replaced by accident. The message names the
/// folder, what is in it, and the two ways on.
pub(crate) fn refuse_existing_results(
    out: &std::path::Path,
    overwrite: bool,
) -> anyhow::Result<()> {
    if overwrite {
        return Ok(());
    }
    let Ok(entries) = std::fs::read_dir(out) else {
        return Ok(());
    };
    let mut held: Vec<String> = entries
        .filter_map(Result::ok)
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n != ".whirlmap.lock")
        .collect();
    if held.is_empty() {
        return Ok(());
    }
    held.sort();
    let shown = held.iter().take(3).cloned().collect::<Vec<_>>().join(", ");
    anyhow::bail!(
        "output folder {} already holds results ({} entries: {shown}{}); pass --overwrite to \
         replace them, or choose another folder with --out",
        out.display(),
        held.len(),
        if held.len() > 3 { ", ..." } else { "" }
    )
}

/// Which file's schema `whirlmap schema` prints.
#[derive(Clone, Copy, clap::ValueEnum)]
enum SchemaKind {
    /// A scene file (`--scene`).
    Scene,
    /// A sweep file (`whirlmap sweep FILE`).
    Sweep,
    /// An ensemble file (`whirlmap ensemble FILE`, `whirlmap adaptive FILE`).
    Ensemble,
}

/// `whirlmap schema`'s options.
#[derive(clap::Args)]
struct SchemaArgs {
    /// The kind of file.
    kind: SchemaKind,
}

/// `whirlmap scene`'s options.
#[derive(clap::Args)]
struct SceneArgs {
    /// Also give the thermal model's and the bearing analysis's parameters their defaults
    /// (`thermal` and `bearing` are `null`, both off, without it; a scene file with them
    /// switches them on).
    #[arg(long)]
    all: bool,
    /// Print the scene's JSON Schema instead: type, default, unit (`x-unit`), allowed range
    /// (`minimum`, `maximum`, or their exclusive forms), source (`x-source`) and description
    /// of every field, derived from the same types the scene is read with.
    #[arg(long, conflicts_with = "all")]
    schema: bool,
}

/// What `whirlmap scene` prints.
fn scene_text(a: &SceneArgs) -> String {
    if a.schema {
        let schema = whirlmap_core::schema::scene_schema();
        return serde_json::to_string_pretty(&schema).expect("the schema serialises");
    }
    Scene::paper_every_field(a.all)
}

#[derive(Subcommand)]
enum Command {
    /// Simulate one drop and print its outputs.
    Drop(DropArgs),
    /// Print the default scene (the paper's) as JSON, every accepted field with its default:
    /// a starting file for --scene. Units, ranges and sources: `--schema`.
    Scene(SceneArgs),
    /// Print the JSON Schema of a scene, sweep or ensemble file, for editors to validate
    /// files against: type, default, unit, allowed range and source of every scene field.
    Schema(SchemaArgs),
    /// Time fourteen reference drops (pendulum and whirl drops at the fidelity presets, model
    /// variants, a high speed, RODAS4 against Rodas5P at a tight tolerance, RADAU5) and one
    /// right-hand-side evaluation.
    Bench(bench::BenchArgs),
    /// Draw the design charts (Figs. 3-6, class map) of a sweep's results directory into
    /// DIR/charts/ as PNG and SVG (exit 2 if DIR holds neither sweep records nor ensemble
    /// contours, 4 if writing fails).
    Render(render_cmd::RenderArgs),
    /// Critical backward-whirl speed per friction coefficient (scan, then bisection).
    Critical(critical_cmd::CriticalArgs),
    /// Run a grid of drops from a JSON sweep spec (exit 1 if any point or orbit drop failed).
    Sweep(sweep_cmd::SweepArgs),
    /// Work-precision study: representative drops at a ladder of tolerances and model
    /// settings against a DOP853 reference (CSV, Markdown, log-log charts).
    Accuracy(accuracy_cmd::AccuracyArgs),
    /// Join the shard folders of a sweep into one result (exit 2 if a point is missing or
    /// twice, or the shards differ in spec, model version or build; 1 if any point failed).
    Merge(merge_cmd::MergeArgs),
    /// Compare two sweep results: class changes, force and power changes beyond thresholds,
    /// critical-speed shifts; a Markdown report with a class map (exit 0 same, 1 changed,
    /// 2 error).
    Compare(compare_cmd::CompareArgs),
    /// Whirl probability per grid cell from seeded ensembles of drops, with probability
    /// contours and Fig. 4 with bands (exit 1 if any drop failed).
    Ensemble(ensemble_cmd::EnsembleCmdArgs),
    /// Adaptive refinement of the whirl boundary over speed x mu (`--compare-full` also runs
    /// the full fine grid and reports the agreement).
    Adaptive(ensemble_cmd::AdaptiveArgs),
}

#[derive(clap::Args)]
struct DropArgs {
    /// Rotor speed at release (r/min), in [-1e6, 1e6] (negative: spinning the other way);
    /// default: the scene's (8000).
    #[arg(long, allow_negative_numbers = true, value_parser = flags::number(flags::speed_range))]
    speed_rpm: Option<f64>,
    /// Dynamic friction coefficient rotor-race, [0, 2]; default: the scene's (0.1).
    #[arg(long, allow_negative_numbers = true, value_parser = flags::number(flags::mu_range))]
    mu: Option<f64>,
    /// Scene file (JSON); any subset of the fields printed by `whirlmap scene`.
    #[arg(long)]
    scene: Option<PathBuf>,
    /// Override one scene parameter, e.g. `--set clearance_m=2e-4 --set solver.rtol=1e-7`.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
    /// Simulated time after release (s).
    #[arg(
        long,
        default_value_t = 1.0,
        allow_negative_numbers = true,
        value_parser = flags::number(flags::duration_range)
    )]
    duration_s: f64,
    /// Print the JSON record instead of a summary.
    #[arg(long)]
    json: bool,
    /// Draw the orbit (Fig. 3 view) to this .png or .svg file.
    #[arg(long)]
    orbit: Option<PathBuf>,
    /// Fidelity preset (draft, standard, reference): sets the tolerance, the integrator and
    /// the reduced model last, over the scene file and --set. Default: the scene's settings.
    #[arg(long)]
    fidelity: Option<whirlmap_core::Fidelity>,
    /// Switch the thermal model on (paper Sec. 3) with the scene's thermal parameters, or the
    /// defaults if the scene has none (applied before --set, so `--set thermal.x=...` works).
    #[arg(long)]
    thermal: bool,
    /// Draw the node temperatures and the thermal load over time to this .png or .svg file
    /// (implies --thermal).
    #[arg(long)]
    temperatures: Option<PathBuf>,
    /// Analyse the touchdown bearing as the drop runs (ball loads, contact pressure against
    /// the 4.2 GPa static limit, fatigue damage, drops to failure) with the paper's pair, or
    /// the scene's `bearing` if it has one (applied before --set, so `--set bearing.x=...`
    /// works). The dynamics do not change.
    #[arg(long)]
    bearing: bool,
}

/// A failure with its exit code.
enum Failure {
    Input(anyhow::Error),
    Solve(anyhow::Error),
    Output(anyhow::Error),
}

/// How a command that ran to its end went: exit 0, or exit 1 when the work finished but
/// flags something (some points failed; `compare`: the runs differ).
pub(crate) enum Done {
    /// Exit 0.
    Clean,
    /// Exit 1.
    Flagged,
}

impl Done {
    /// `Flagged` when `flag`, else `Clean`.
    pub(crate) fn flagged_if(flag: bool) -> Self {
        if flag {
            Done::Flagged
        } else {
            Done::Clean
        }
    }
}

/// What every command returns; [`run`] is the one place that prints an error and turns the
/// result into the exit code.
pub(crate) type CmdResult = Result<Done, Failure>;

impl Failure {
    /// The failure for one of the library's exit codes (2 bad input, 3 a drop or search
    /// failed, 4 an output could not be written).
    pub(crate) fn coded(code: u8, error: impl std::fmt::Display) -> Self {
        let e = anyhow::anyhow!("{error}");
        match code {
            2 => Failure::Input(e),
            3 => Failure::Solve(e),
            _ => Failure::Output(e),
        }
    }

    fn code(&self) -> u8 {
        match self {
            Failure::Input(_) => 2,
            Failure::Solve(_) => 3,
            Failure::Output(_) => 4,
        }
    }
    fn error(&self) -> &anyhow::Error {
        match self {
            Failure::Input(e) | Failure::Solve(e) | Failure::Output(e) => e,
        }
    }
}

/// Checks that `path` can be written before any simulation runs: its folder exists and a
/// file can be created in it. The error names the path and the cause.
pub(crate) fn check_writable(path: &Path) -> anyhow::Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    if !dir.is_dir() {
        anyhow::bail!(
            "cannot write {}: {}",
            path.display(),
            if dir.exists() {
                format!("{} is a file, not a folder", dir.display())
            } else {
                format!("the folder {} does not exist", dir.display())
            }
        );
    }
    if path.is_dir() {
        anyhow::bail!("cannot write {}: it is a folder", path.display());
    }
    let probe = dir.join(format!(".whirlmap-probe-{}", std::process::id()));
    let created = std::fs::File::create(&probe);
    let _ = std::fs::remove_file(&probe);
    created
        .map(|_| ())
        .map_err(|e| anyhow::anyhow!("cannot write {}: {e}", path.display()))
}

/// Default scene, then the scene file, then `--set`, then the explicit flags; validated.
fn build_scene(
    file: Option<&Path>,
    sets: &[String],
    speed_rpm: Option<f64>,
    mu: Option<f64>,
) -> anyhow::Result<Scene> {
    build_scene_with(file, sets, speed_rpm, mu, Sections::default())
}

/// The optional scene sections a flag switches on (`--thermal`, `--bearing`), with their
/// defaults unless the scene file has them, before the `--set` overrides.
#[derive(Clone, Copy, Default)]
struct Sections {
    /// `--thermal` (or `--temperatures`).
    thermal: bool,
    /// `--bearing`.
    bearing: bool,
}

/// [`build_scene`], switching on the sections in `on` (the thermal model, the bearing
/// analysis; defaults, unless the scene file has them) before the `--set` overrides, so
/// `--bearing --set bearing.rows=3` works as `--thermal --set thermal.x=...` does.
fn build_scene_with(
    file: Option<&Path>,
    sets: &[String],
    speed_rpm: Option<f64>,
    mu: Option<f64>,
    on: Sections,
) -> anyhow::Result<Scene> {
    let mut scene = match file {
        Some(p) => {
            let text = std::fs::read_to_string(p)
                .with_context(|| format!("cannot read scene file {}", p.display()))?;
            whirlmap_core::json::from_str::<Scene>(&text).map_err(|e| {
                anyhow::anyhow!(
                    "scene file {}: {}",
                    p.display(),
                    whirlmap_sweep::overrides::with_suggestion(&e.to_string())
                )
            })?
        }
        None => Scene::paper(),
    };
    if on.thermal && scene.thermal.is_none() {
        scene.thermal = Some(whirlmap_core::ThermalParams::default());
    }
    if on.bearing && scene.bearing.is_none() {
        scene.bearing = Some(whirlmap_core::bearing::BearingPair::paper_71908_cd());
    }
    for s in sets {
        apply_assignment(&mut scene, s).with_context(|| format!("--set {s}"))?;
    }
    if let Some(v) = speed_rpm {
        scene.speed_rpm = v;
    }
    if let Some(v) = mu {
        scene.mu_dynamic = v;
    }
    scene.validate().map_err(|e| {
        // A value given by a flag is named by the flag (and the field it sets).
        let flag = match e.field.as_str() {
            "mu_dynamic" if mu.is_some() => Some("--mu"),
            "speed_rpm" if speed_rpm.is_some() => Some("--speed-rpm"),
            _ => None,
        };
        match flag {
            Some(flag) => anyhow::anyhow!(
                "invalid {flag} = {} (the scene's {}): allowed {}",
                e.value,
                e.field,
                e.allowed
            ),
            None => e.into(),
        }
    })?;
    Ok(scene)
}

/// `x` to three significant figures, without trailing zeros (60, 43.8, 0.375, 0.0004).
fn three_figures(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    let scale = 10f64.powi(2 - x.abs().log10().floor() as i32);
    (x * scale).round() / scale
}

/// The scene's physical settings that differ from the paper's, for a chart title:
/// `, unbalance_m 5e-6, support_damper radial_only` (the numerics, `solver.*` and
/// `classification.*`, and the thermal model's parameters are left out; at most three, then
/// "and N more").
fn settings_note(scene: &Scene) -> String {
    let changes: Vec<String> = whirlmap_core::scene::scene_changes(scene)
        .into_iter()
        .filter(|(k, _)| !k.starts_with("solver.") && !k.starts_with("classification."))
        .map(|(k, v)| match v {
            serde_json::Value::String(s) => format!("{k} {s}"),
            serde_json::Value::Object(_) if k == "thermal" => "thermal model".to_string(),
            v => format!("{k} {v}"),
        })
        .collect();
    match changes.len() {
        0 => String::new(),
        n if n <= 3 => format!(", {}", changes.join(", ")),
        n => format!(", {} and {} more", changes[..3].join(", "), n - 3),
    }
}

/// `x` with `decimals` digits after the point, without the sign of a value that rounds to
/// zero: `-0.0000` for a drop without spin's initial energy of -3e-9 J reads `0.0000`.
fn fixed(x: f64, decimals: usize) -> String {
    let s = format!("{x:.decimals$}");
    match s.strip_prefix('-') {
        Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_string(),
        _ => s,
    }
}

/// Says on standard error which `--set` values the preset `f` replaces (its
/// [`whirlmap_core::Fidelity::KEYS`], also inside a whole `solver` section): the preset is
/// applied after them, so they would otherwise vanish without a word.
pub(crate) fn warn_preset_overrides(f: whirlmap_core::Fidelity, sets: &[String]) {
    for s in sets {
        let (key, value) = s.split_once('=').unwrap_or((s.as_str(), ""));
        let key = key.trim();
        if whirlmap_core::Fidelity::KEYS.contains(&key) {
            errln!(
                "warning: --fidelity {} sets the numerics, so --set {s} has no effect (leave \
                 out --fidelity to choose them yourself)",
                f.name()
            );
        } else if key == "solver" {
            // A whole section: the preset replaces its keys of the preset's, the rest stay.
            let given = serde_json::from_str::<serde_json::Value>(value.trim()).ok();
            let replaced: Vec<String> = given
                .as_ref()
                .and_then(|v| v.as_object())
                .into_iter()
                .flat_map(|o| o.keys())
                .filter(|k| whirlmap_core::Fidelity::KEYS.contains(&format!("solver.{k}").as_str()))
                .cloned()
                .collect();
            if !replaced.is_empty() {
                errln!(
                    "warning: --fidelity {} sets the numerics, so {} of --set {s} has no effect \
                     (its other keys do; leave out --fidelity to choose them yourself)",
                    f.name(),
                    replaced.join(", ")
                );
            }
        }
    }
}

/// Says on standard error which values of the spec file `path`'s `scene` its `fidelity`
/// preset replaces ([`whirlmap_sweep::spec::replaced_by_fidelity`]), for a sweep or an
/// ensemble file that has already been read and checked: they would otherwise vanish without a
/// word.
pub(crate) fn warn_spec_preset_overrides(path: &Path) {
    let Ok(text) = std::fs::read_to_string(path) else {
        return;
    };
    let Ok(spec) =
        serde_json::from_str::<serde_json::Value>(whirlmap_core::json::without_bom(&text))
    else {
        return;
    };
    let preset = spec["fidelity"].as_str().unwrap_or_default();
    for (key, value) in whirlmap_sweep::spec::replaced_by_fidelity(&spec) {
        errln!(
            "warning: {}: fidelity {preset} sets the numerics, so {key} = {value} has no \
             effect (leave out fidelity to choose them yourself, or give the value on an axis, \
             which is applied after the preset)",
            path.display()
        );
    }
}

/// The integrator settings a drop ran with, and the preset they are, if any: `rodas4, rtol
/// 1e-4, race tolerance x1000 (the draft preset)`.
fn numerics_line(scene: &Scene) -> String {
    let s = &scene.solver;
    let method = serde_json::to_value(s.method)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_default();
    let mut parts = vec![method, format!("rtol {:e}", s.rtol)];
    if s.race_atol_scale != 1.0 {
        parts.push(format!("race tolerance x{}", s.race_atol_scale));
    }
    if s.race_velocity_atol_from_force {
        parts.push("race velocity tolerance from the contact force".to_string());
    }
    if s.method.is_multistep() && s.bdf_max_order != SolverSettings::default().bdf_max_order {
        parts.push(format!("multistep orders 1 to {}", s.bdf_max_order));
    }
    if scene.quasi_static_race {
        parts.push("quasi-static race".to_string());
    }
    let preset = whirlmap_core::Fidelity::ALL
        .into_iter()
        .find(|f| *s == f.solver() && !scene.quasi_static_race);
    match preset {
        Some(f) => format!("{} (the {} preset)", parts.join(", "), f.name()),
        None => parts.join(", "),
    }
}

fn run_drop(a: &DropArgs) -> Result<(), Failure> {
    let on = Sections {
        thermal: a.thermal || a.temperatures.is_some(),
        bearing: a.bearing,
    };
    let mut scene = build_scene_with(a.scene.as_deref(), &a.set, a.speed_rpm, a.mu, on)
        .map_err(Failure::Input)?;
    // A `--set thermal=null` (or `bearing=null`) after the flag that asks for the model.
    if on.thermal && scene.thermal.is_none() {
        let flag = if a.temperatures.is_some() {
            "--temperatures"
        } else {
            "--thermal"
        };
        return Err(Failure::Input(anyhow::anyhow!(
            "{flag} needs the thermal model, which `--set thermal=null` switches off: drop one \
             of the two"
        )));
    }
    if on.bearing && scene.bearing.is_none() {
        return Err(Failure::Input(anyhow::anyhow!(
            "--bearing needs the bearing analysis, which `--set bearing=null` switches off: drop \
             one of the two"
        )));
    }
    if let Some(f) = a.fidelity {
        warn_preset_overrides(f, &a.set);
        f.apply(&mut scene);
    }
    // Output paths are checked before the drop runs, not after.
    for p in [&a.orbit, &a.temperatures].into_iter().flatten() {
        ImageFormat::from_path(p).map_err(|e| Failure::Input(e.into()))?;
        whirlmap_plot::render::check_writable(p).map_err(|e| Failure::Output(e.into()))?;
    }
    let opts = DropOptions {
        duration_s: a.duration_s,
        orbit_points: a.orbit.as_ref().map(|_| 20_000),
        ..Default::default()
    };
    opts.validate().map_err(|e| {
        // The duration is the flag's: named by it, as `critical` names its own.
        Failure::Input(match e.field.as_str() {
            "duration_s" => {
                anyhow::anyhow!("invalid --duration-s = {}: allowed {}", e.value, e.allowed)
            }
            _ => e.into(),
        })
    })?;
    let start = Instant::now();
    let report = simulate(&scene, &opts)
        .map_err(|e| Failure::Solve(anyhow::anyhow!("simulation failed ({}): {e}", e.kind())))?;
    let wall_s = start.elapsed().as_secs_f64();
    let record = DropRecord::from_report(&report);
    // The outputs are printed before the charts are drawn: a chart that cannot be written (a
    // full disk) loses nothing of the drop.
    if a.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&record).expect("records serialise")
        );
    } else {
        print_summary(&scene, &report, &record, wall_s);
    }
    if let (Some(path), Some(orbit)) = (&a.orbit, &report.orbit) {
        let title = format!(
            "{:.0} r/min, μ = {:.2}{}: {}",
            scene.speed_rpm,
            scene.mu_dynamic,
            settings_note(&scene),
            record.class.label()
        );
        draw_orbit(path, &title, orbit).map_err(|e| Failure::Output(e.into()))?;
    }
    if let (Some(path), Some(th)) = (&a.temperatures, &report.thermal) {
        let title = format!(
            "{:.0} r/min, μ = {:.2}{}: touchdown bearing temperatures over {} s",
            scene.speed_rpm,
            scene.mu_dynamic,
            settings_note(&scene),
            three_figures(report.end_time_s)
        );
        draw_temperatures(path, &title, &th.series).map_err(|e| Failure::Output(e.into()))?;
    }
    if !a.json {
        if let Some(p) = &a.orbit {
            outln!("  orbit chart           {}", p.display());
        }
        if let Some(p) = &a.temperatures {
            outln!("  temperature chart     {}", p.display());
        }
    }
    Ok(())
}

fn print_summary(scene: &Scene, r: &DropReport, rec: &DropRecord, wall_s: f64) {
    let f = &r.features;
    let e = &r.energy;
    let why = match r.stop_reason {
        whirlmap_core::StopReason::DurationReached => "duration reached",
        whirlmap_core::StopReason::WhirlDecided => "stopped: whirl decided",
        whirlmap_core::StopReason::StopSpeedReached => "stopped: stop speed reached",
    };
    let extended = if r.extension_s > 0.0 {
        format!(
            ", extended by {:.3} s for the class to settle",
            r.extension_s
        )
    } else {
        String::new()
    };
    outln!(
        "whirlmap drop: {} r/min, mu_d {}, {:.4} s simulated ({why}{extended})",
        // The inputs as given (a search's 4390.625 r/min is not 4391).
        whirlmap_core::scene::num(scene.speed_rpm),
        whirlmap_core::scene::num(scene.mu_dynamic),
        r.end_time_s
    );
    outln!(
        "  class                 {} ({})",
        rec.class.label(),
        rec.class_reason.describe()
    );
    outln!("  first contact force   {:.1} N", f.first_contact_force_n);
    outln!(
        "  max contact force     {:.1} N (at {:.2} ms)",
        f.max_contact_force_n,
        f.max_contact_force_time_s * 1e3
    );
    outln!("  peak friction power   {:.1} W", f.peak_friction_power_w);
    outln!("  peak heat power       {:.1} W", f.peak_heat_power_w);
    // The same feature (the contact point's mean angular rate): a whirl frequency when the
    // orbit whirls, the contact point's drift when it settled otherwise, its rate so far when
    // it did not settle.
    use whirlmap_sweep::classify::OrbitClass;
    let (name, note) = match rec.class {
        c if c.is_whirl() => ("whirl frequency      ", "negative = against the spin"),
        OrbitClass::Unresolved => (
            "contact point rate   ",
            "the whirl-frequency feature; not settled",
        ),
        _ => (
            "contact point drift  ",
            "the whirl-frequency feature; no whirl",
        ),
    };
    outln!("  {name} {:+.2} Hz ({note})", f.whirl_frequency_hz);
    outln!(
        "  contact point turns   {:+.2} since first touch, {:+.2} before settling, {:+.0} consecutive carried at the end",
        f.net_whirl_turns, f.transient_whirl_turns, f.whirl_streak_turns
    );
    let w = &f.window.stats;
    outln!(
        "  final window          {:.3}-{:.3} s: contact duty {:.3}, mean angle {:+.1} deg from the bottom, range {:.1} deg, {:+.2} turns; {} impacts in all",
        w.start_s,
        w.end_s,
        w.contact_duty,
        w.angle_mean_rad.to_degrees(),
        w.angle_range_rad.to_degrees(),
        w.net_turns,
        f.impacts
    );
    outln!(
        "  final speeds          rotor {:.0} r/min, race {:.0} r/min",
        f.final_rotor_speed_rpm,
        f.final_race_speed_rpm
    );
    outln!(
        "  energy (J)            initial {} = final {} + friction {} + damping {} + drag {}  (residual {:.1e})",
        fixed(e.initial_j, 4),
        fixed(e.final_j, 4),
        fixed(e.friction_heat_j, 4),
        fixed(e.damping_loss_j, 6),
        fixed(e.drag_work_j, 4),
        e.residual_rel
    );
    outln!(
        "  work                  {} RHS evaluations, {} steps ({} rejected), {} events, {:.3} s wall",
        r.stats.rhs_evals, r.stats.steps, r.stats.rejected, r.stats.events, wall_s
    );
    outln!("  numerics              {}", numerics_line(scene));
    if let Some(th) = &r.thermal {
        print_thermal(th, r.end_time_s);
    }
    if let Some(b) = &r.bearing {
        outln!(
            "  bearing               peak ball load {:.0} N, contact pressure {:.2} GPa (static safety factor {:.2} against {} GPa)",
            b.peak_ball_load_n,
            b.peak_contact_pressure_pa / 1e9,
            b.static_safety_factor,
            scene
                .bearing
                .as_ref()
                .map_or(4.2, |p| p.static_limit_pressure_pa / 1e9)
        );
        outln!(
            "  fatigue               damage {:.3e} per drop, {:.3e} drops to failure (L10; {})",
            b.damage_per_drop,
            b.drops_to_failure,
            if r.stop_reason == whirlmap_core::StopReason::WhirlDecided {
                "a whirl run stopped at its turn count: the damage of those turns only"
            } else {
                "ISO 281 load-life, Palmgren-Miner"
            }
        );
    }
    outln!("  scene hash            {}", r.scene_hash);
}

fn print_thermal(th: &whirlmap_core::ThermalReport, end_time_s: f64) {
    use whirlmap_core::thermal::network::node::NAMES;
    outln!("  temperatures (K)      node: final / peak");
    for (name, n) in NAMES.iter().zip(th.temperatures_k.as_array()) {
        outln!("    {name:<20}{:.2} / {:.2}", n.final_k, n.peak_k);
    }
    outln!(
        "  thermal load F_th     peak {:.2} N, final {:.2} N",
        th.peak_thermal_load_n,
        th.final_thermal_load_n
    );
    let h = &th.heat;
    outln!(
        "  heat (J)              H_s {:.2} + H_i {:.2} + H_o {:.2} = stored {:.2} + lost to ambient {:.2}",
        h.h_s_j, h.h_i_j, h.h_o_j, h.stored_j, h.lost_to_ambient_j
    );
    if let Some(last) = th.series.last() {
        outln!(
            "  heat power H          {:.1} W at the end (macro-step mean)",
            last.heat_w
        );
    }
    outln!(
        "  thermal work          {} network steps ({:.0} per simulated second)",
        th.network_steps,
        th.network_steps as f64 / end_time_s.max(1e-12)
    );
}

fn main() -> ExitCode {
    ExitCode::from(output::finish(run()))
}

/// The most worker threads any command takes (`--threads`'s range).
const MAX_THREADS: usize = whirlmap_sweep::pool::MAX_THREADS;

/// Refuses a thread count from the environment above [`MAX_THREADS`]
/// ([`whirlmap_sweep::pool::env_threads_beyond_range`]) for a command that takes rayon's
/// default pool: one without `--threads`.
fn check_thread_env(command: &Command) -> Result<(), Failure> {
    let default_pool = match command {
        Command::Critical(_) | Command::Merge(_) | Command::Compare(_) | Command::Render(_) => true,
        Command::Sweep(a) => a.threads.is_none(),
        Command::Ensemble(a) => a.common.threads.is_none(),
        Command::Adaptive(a) => a.common.threads.is_none(),
        _ => false,
    };
    match whirlmap_sweep::pool::env_threads_beyond_range() {
        Some(e) if default_pool => Err(Failure::Input(anyhow::anyhow!(
            "{e}, or give --threads where the command has it"
        ))),
        _ => Ok(()),
    }
}

/// Runs the command; returns its exit code.
fn run() -> u8 {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        // A usage error (exit 2), or `--help` and `--version` (exit 0, and exit 4 when they
        // cannot be written, `whirlmap --help > /dev/full`, but not for a closed pipe, as
        // `output` says), in clap's words.
        Err(e) => {
            return match e.print() {
                Err(cause) if !e.use_stderr() && cause.kind() != std::io::ErrorKind::BrokenPipe => {
                    errln!("error: cannot write standard output: {cause}");
                    4
                }
                _ => e.exit_code() as u8,
            };
        }
    };
    if let Err(f) = check_thread_env(&cli.command) {
        errln!("error: {:#}", f.error());
        return f.code();
    }
    let result: CmdResult = match &cli.command {
        Command::Drop(a) => run_drop(a).map(|()| Done::Clean),
        Command::Scene(a) => {
            outln!("{}", scene_text(a));
            Ok(Done::Clean)
        }
        Command::Schema(a) => {
            let schema = match a.kind {
                SchemaKind::Scene => whirlmap_core::schema::scene_schema(),
                SchemaKind::Sweep => whirlmap_sweep::schema::sweep_schema(),
                SchemaKind::Ensemble => whirlmap_sweep::schema::ensemble_schema(),
            };
            outln!(
                "{}",
                serde_json::to_string_pretty(&schema).expect("a schema serialises")
            );
            Ok(Done::Clean)
        }
        Command::Bench(a) => bench::run(a).map(|()| Done::Clean).map_err(Failure::Solve),
        Command::Render(a) => render_cmd::run(a)
            .map(|()| Done::Clean)
            .map_err(|f| match f {
                render_cmd::RenderFailure::Input(e) => Failure::Input(e),
                render_cmd::RenderFailure::Output(e) => Failure::Output(e),
            }),
        Command::Critical(a) => critical_cmd::run(a),
        Command::Sweep(a) => sweep_cmd::run(a),
        Command::Accuracy(a) => accuracy_cmd::run_cmd(a).map(|()| Done::Clean),
        Command::Merge(a) => merge_cmd::run(a),
        Command::Compare(a) => compare_cmd::run(a),
        Command::Ensemble(a) => ensemble_cmd::run_ensemble_cmd(a),
        Command::Adaptive(a) => ensemble_cmd::run_adaptive_cmd(a),
    };
    match result {
        Ok(Done::Clean) => 0,
        Ok(Done::Flagged) => 1,
        Err(f) => {
            errln!("error: {:#}", f.error());
            f.code()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::fixed;

    #[test]
    fn fixed_drops_the_sign_of_a_rounded_zero_only() {
        assert_eq!(fixed(-3e-9, 4), "0.0000");
        assert_eq!(fixed(-0.0, 2), "0.00");
        assert_eq!(fixed(-0.00006, 4), "-0.0001");
        assert_eq!(fixed(-0.0086, 4), "-0.0086");
        assert_eq!(fixed(12.25, 1), "12.2");
        assert_eq!(fixed(f64::NAN, 4), "NaN");
    }
}
