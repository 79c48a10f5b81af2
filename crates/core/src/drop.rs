//! One drop, end to end: release, integrate through every located mode switch, stop at the
//! duration or when the whirl stopping rule decides, and audit the energy.

use crate::bearing::{BearingAnalysis, BearingReport};
use crate::classify::{classify, Verdict};
use crate::error::{InvalidParameter, SolveError};
use crate::model::{ix, DropSystem, Mode, N};
use crate::monitor::{Features, Monitor, WhirlDecided};
use crate::ode::{
    run_hybrid, Dop853, Dopri5, Finish, HybridObserver, JumpRules, NoObserver, Observer, Rodas4,
    Rodas5p, Ros34pw2, Stats, StepControl, StepView, Stepper,
};
use crate::orbit::Orbit;
use crate::scene::{Method, Scene};
use crate::thermal::{ThermalReport, ThermalRun};
use serde::{Deserialize, Serialize};
use std::ops::ControlFlow;

/// Version of the model and its outputs; part of every record key. Bump it when a change
/// alters results for the same scene.
///
/// - 13: the BDF (and the NDF) of `rodas4_bdf`, `rodas4_ndf` and `bdf` go up to order 4,
///   not 5 (`solver.bdf_max_order`): order 5 is unstable on the lightly damped modes of the
///   rotor and race rolling in the race over most of its step sizes, so the 1 s pendulum
///   drop took 1.4 times the steps and twice the rejections it takes at order 4. Later in
///   version 13 the `draft` preset became RODAS4 then BDF as well: a preset sets the scene's
///   numerics, so that moves no result of a given scene; a record's scene hash, and a
///   sweep manifest's `preset_solver`, tell the two `draft`s apart
///   (docs/accuracy.md#why-draft-is-rodas4-then-bdf).
/// - 12: the `standard` numerics step with RODAS4 after every mode switch and with the BDF,
///   at a tenth of the tolerance, once the contact has been carried for 2 ms and 12 steps
///   (`solver.method = "rodas4_bdf"`, [`crate::ode::Rodas4Bdf`]): as close to `reference`
///   as RODAS4 was, for about 0.7 of its time on a 1 s drop.
/// - 11: the model's fractional powers (the contact's Hertz law, eq. 7, and Palmgren's drag,
///   eqs. 12-13) come from the model's own `pow` (`model/pow.rs`, within 1.1e-14 of the exact
///   powers over the model's usual arguments), which cut one right-hand-side evaluation by a
///   quarter; results move in their last digits.
/// - 10: the event loop watches a guard that starts a step at exactly zero and locates its
///   going below zero, and a guard at zero when a step starts that is below zero at another
///   guard's event takes its own switch there (before, a guard was watched only once
///   positive: a contact whose guard reached exactly zero, the penetration exactly 0 at a
///   graze, and closed again went unseen, and the rotor fell through the race).
/// - 9: a guard that switched at an event (the located one included) switches once more
///   when another guard's switch at the same event sent it below zero (a stick that the race's
///   lift-off puts past its static limit ends at once).
/// - 8: a guard that crossed together with the located one, or that a mode switch sent
///   below zero, takes its own switch (`take_follow_on_jumps` in `ode/hybrid.rs`); a race
///   without gravity starts on its support; a contact stepped over, or friction heat below
///   zero by more than half the drop's energy, ends the drop with the typed `unphysical`
///   error.
/// - 7: the `standard` numerics widen the race's velocity tolerance in loaded contact to
///   `rtol F_n / max(c1, c2)` (`solver.race_velocity_atol_from_force`), where the race's
///   velocity had set RODAS4's step, and hold every other race tolerance to the rotor's
///   (`solver.race_atol_scale` default 1, was 30; with the radial-only damper, which widens
///   nothing, that makes drops dearer and closer to `reference`).
/// - 6: the `standard` numerics are RODAS4 on the model's full Jacobian (the accumulators'
///   rows, the sticking constraint's and the drag's slopes) at rtol 3e-5, with the
///   free-flight gap bound and the race tolerance x30: four times closer to `reference` than
///   DOPRI5 at rtol 3e-5 on the main job's grid, for 0.69 of its CPU time.
/// - 5: the `standard` numerics are DOPRI5 at rtol 3e-5: ROS34PW2 with the race tolerance
///   x1000 missed the accuracy budget by up to 12 % in the maximum force of bouncing
///   sequences and became the `draft` preset (until RODAS4 with the same tolerances
///   replaced it, docs/accuracy.md#why-draft-is-rodas4-then-bdf).
/// - 4: the `standard` numerics (ROS34PW2, gap bound, race tolerance x1000, rtol 1e-4) are
///   the scene's default solver settings, every solver setting is in the scene's JSON, and
///   whirl turn times are interpolated between the angle's samples.
/// - 3: the isotropic support damper is the default ([`crate::scene::SupportDamper`]);
///   classes describe the settled motion on a final window, undecided runs are extended,
///   and the whirl rule counts consecutive carried turns
///   ([`crate::classify`](mod@crate::classify)).
/// - 2: a slip entered against the drifted slip velocity takes its sign.
pub const MODEL_VERSION: u32 = 13;

/// Largest first step after a mode switch (s): see [`Stepper::cap_next_step`].
pub(crate) const STEP_AFTER_SWITCH_S: f64 = 1e-7;

/// How to run a drop (what is not physics).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DropOptions {
    /// Simulated time after release (s). Default 1. Allowed (0, 3600].
    pub duration_s: f64,
    /// Contact episodes separated by less than this count as one impact (s). Default 0.5 ms
    /// (the light race can leave the rotor for a fraction of a millisecond inside one impact;
    /// docs/model.md#impacts-and-the-first-contact-force).
    pub impact_merge_s: f64,
    /// Record the orbit with about this many samples (`None`: O(1) memory, no orbit).
    pub orbit_points: Option<usize>,
}

impl Default for DropOptions {
    fn default() -> Self {
        Self {
            duration_s: 1.0,
            impact_merge_s: 0.5e-3,
            orbit_points: None,
        }
    }
}

impl DropOptions {
    /// Checks the options; the error names the field.
    pub fn validate(&self) -> Result<(), InvalidParameter> {
        if !(self.duration_s.is_finite() && self.duration_s > 0.0 && self.duration_s <= 3600.0) {
            return Err(InvalidParameter::new(
                "duration_s",
                crate::scene::num(self.duration_s),
                "(0, 3600] s",
            ));
        }
        if !(self.impact_merge_s.is_finite() && self.impact_merge_s >= 0.0) {
            return Err(InvalidParameter::new(
                "impact_merge_s",
                self.impact_merge_s,
                ">= 0 s",
            ));
        }
        if self.orbit_points == Some(0) || self.orbit_points.is_some_and(|n| n > 10_000_000) {
            return Err(InvalidParameter::new(
                "orbit_points",
                self.orbit_points.unwrap_or(0),
                "[1, 1e7]",
            ));
        }
        Ok(())
    }
}

/// Why a drop ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StopReason {
    /// The requested duration (or its extension, see [`DropReport::extension_s`]) was
    /// simulated.
    DurationReached,
    /// The contact point made the scene's `whirl_stop_turns` consecutive carried turns in
    /// one direction: whirl is decided, and in a rigid housing it would only grow.
    WhirlDecided,
    /// The rotor spin fell below the scene's `stop_speed_rpm`: the coast-down is over.
    StopSpeedReached,
}

impl StopReason {
    /// The reason in words, for a person: `duration reached`, `whirl decided`, `stop speed
    /// reached`.
    pub fn describe(self) -> &'static str {
        match self {
            StopReason::DurationReached => "duration reached",
            StopReason::WhirlDecided => "whirl decided",
            StopReason::StopSpeedReached => "stop speed reached",
        }
    }
}

/// The energy audit: initial = final + friction heat + damping loss + drag work.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct EnergyAudit {
    /// Mechanical energy at release (J): kinetic, gravitational (zero at y = 0), elastic.
    pub initial_j: f64,
    /// Mechanical energy at the end (J).
    pub final_j: f64,
    /// Friction heat at the rotor-race contact, the integral of H_s (J).
    pub friction_heat_j: f64,
    /// Energy taken by the two contact dampers (J), including the elastic energy a contact
    /// holds when its damper-never-pulls switch opens it while still overlapping (and, with
    /// opposite sign, when it re-seats while overlapping).
    pub damping_loss_j: f64,
    /// Work of the Palmgren drag torque (J): the bearing's heat.
    pub drag_work_j: f64,
    /// |initial - final - losses| / scale, with scale the largest of |initial|, |final|, the
    /// total loss and the drop energy m_r g s; infinite when an energy is not finite. Above
    /// [`AUDIT_THRESHOLD`] the drop fails ([`SolveError::EnergyAudit`]).
    pub residual_rel: f64,
}

/// Fails a drop that ends with the rotor through the race while the contact is not acting
/// ([`SolveError::Unphysical`]): its centre more than the clearance beyond the race's contact
/// circle, with eq. 7's force positive there (the elastic term outweighs a pulling damper), so
/// the contact should act and a step passed over its closing. A contact that opened while
/// overlapping because its damper would pull (eq. 7's never-pull rule) is not this: its raw
/// force is negative. With the contact acting, so deep a penetration is the Hertz law's answer
/// to a load far beyond the scene's (a 400 t rotor on the paper's race), and is kept.
fn check_physical(sys: &DropSystem, y: &[f64; N], t: f64) -> Result<(), SolveError> {
    let s = sys.clearance_m();
    let f = sys.forces_in(y, sys.mode);
    if f.delta_m > s && f.normal_raw_n > 0.0 && !sys.mode.contact {
        return Err(SolveError::Unphysical {
            t_s: t,
            what: format!(
                "the rotor's centre is {:.6e} m from the race's, through the race (clearance \
                 {s:.6e} m), with the contact not acting: a contact was stepped over",
                f.dist_m
            ),
        });
    }
    Ok(())
}

/// Friction only dissipates (eq. 17's H_s = F_t v_rel is never negative in slip, and is zero
/// in stick but for the drift of v_rel), so a drop whose friction heat ends below zero by more
/// than [`AUDIT_THRESHOLD`] of its initial energy (or of the drop energy m g s, if larger)
/// has had friction make energy, which the audit cannot see: it checks that the books
/// balance, and they do. A safety net for gross failures, not an accuracy check (a sticking
/// contact's drift gives heat dips below 1e-6 J in the physics tests at `standard`; the
/// former `draft`, ROS34PW2, let drops without spin released off centre dip to about -40 % of
/// m g s, which passed): a wrong mode switch
/// that left a slip pushing along its own slip velocity made -1788 J of "friction heat" in a
/// drop without spin, whose only energy was the fall's 8.5 mJ, and the audit passed
/// (docs/model.md#guards-that-reach-zero-at-a-switch).
fn check_friction_heat(energy: &EnergyAudit, drop_energy_j: f64, t: f64) -> Result<(), SolveError> {
    let scale = energy.initial_j.abs().max(drop_energy_j);
    if energy.friction_heat_j < -AUDIT_THRESHOLD * scale {
        return Err(SolveError::Unphysical {
            t_s: t,
            what: format!(
                "the friction heat is {:.6e} J, below zero by more than {AUDIT_THRESHOLD} of the \
                 larger of the initial energy and the drop energy m g s ({:.6e} J): friction \
                 made energy",
                energy.friction_heat_j, scale
            ),
        });
    }
    Ok(())
}

/// The largest energy audit residual a drop may have ([`EnergyAudit::residual_rel`]); above
/// it the drop fails with [`SolveError::EnergyAudit`].
///
/// Measured with `cargo run --release --example audit_residuals` (the full extremes matrix
/// and drops without spin, where the only energy is the fall's m g s and the relative
/// residual is largest). The residual of a sound drop is integration error and grows with
/// the tolerance. Model version 11 (`--quick`: the reduced matrix of the CI test): at most
/// 2.1e-5 at the scenes' own tolerances (the default RODAS4 at rtol 3e-5 with the race's
/// velocity tolerance from the contact force; version 6 gave 8.5e-6, version 5's DOPRI5
/// 2.9e-4), 7.1e-4 at rtol 1e-3, 8.3e-2 at rtol 1e-2, the loosest a scene allows; 3.0e-4 with
/// the `draft` preset and 3.1e-2 with it at no spin and no damping (30 ms).
/// Drops whose books are broken, with energy created (negative losses, e.g. the race's
/// absolute tolerance loosened 1e4-fold under the explicit DOPRI5 stepper at no spin),
/// measured 1.0 to 1.7, as did a rotor inertia of 1e-300 kg m^2 that validation now
/// refuses. 0.5 lies between the two. An undamped drop without spin over a full second closes
/// to 3.6e-3 at the `draft` preset (as RODAS4, and as RODAS4 then BDF since 2026-11-29);
/// the former `draft` (ROS34PW2 with the race's tolerances
/// widened) crossed the threshold there, damping the undamped contact oscillations
/// numerically and losing 0.88-0.91 of the fall's energy, so that drop failed, rightly, since
/// its numbers were not to be trusted (docs/accuracy.md#energy-audit).
pub const AUDIT_THRESHOLD: f64 = 0.5;

impl EnergyAudit {
    /// The audit of a drop from its energies (J) and the drop energy m g s (J). The residual
    /// is `|initial - final - losses| / scale`, with `scale` the largest of |initial|,
    /// |final|, |losses| and the drop energy. Should that overflow (energies near the largest
    /// float), every term is divided by the largest magnitude before it is summed. A
    /// non-finite energy gives an infinite residual: an audit that cannot be closed has
    /// failed, it has not passed with 0.
    pub fn new(
        initial_j: f64,
        final_j: f64,
        friction_heat_j: f64,
        damping_loss_j: f64,
        drag_work_j: f64,
        drop_energy_j: f64,
    ) -> Self {
        let terms = [
            initial_j,
            final_j,
            friction_heat_j,
            damping_loss_j,
            drag_work_j,
            drop_energy_j,
        ];
        let residual_rel = if !terms.iter().all(|v| v.is_finite()) {
            f64::INFINITY
        } else {
            let losses = friction_heat_j + damping_loss_j + drag_work_j;
            let scale = initial_j
                .abs()
                .max(final_j.abs())
                .max(losses.abs())
                .max(drop_energy_j);
            let direct = (initial_j - final_j - losses).abs() / scale;
            if scale.is_finite() && direct.is_finite() {
                direct
            } else {
                // Overflow: the same quantities with every term scaled first.
                let big = terms.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
                let [i, f, h, d, w, m] = terms.map(|v| v / big);
                let l = h + d + w;
                (i - f - l).abs() / i.abs().max(f.abs()).max(l.abs()).max(m)
            }
        };
        Self {
            initial_j,
            final_j,
            friction_heat_j,
            damping_loss_j,
            drag_work_j,
            residual_rel,
        }
    }
}

/// What a drop was asked to do: the operating point, the simulated time asked for and every
/// scene field that differs from the paper's scene, so that a record can be read without
/// the file or command that made it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DropInputs {
    /// Rotor speed at release (r/min).
    pub speed_rpm: f64,
    /// Dynamic friction coefficient rotor-race (eq. 8).
    pub mu: f64,
    /// Simulated time asked for (s), before any extension by the classifier.
    pub duration_s: f64,
    /// Every other scene field that differs from [`Scene::paper`], by dotted key
    /// ([`crate::scene::scene_changes`]); empty for the paper's scene.
    pub scene_changes: std::collections::BTreeMap<String, serde_json::Value>,
}

impl DropInputs {
    /// The inputs of a drop of `scene` run for `duration_s`.
    pub fn new(scene: &Scene, duration_s: f64) -> Self {
        Self {
            speed_rpm: scene.speed_rpm,
            mu: scene.mu_dynamic,
            duration_s,
            scene_changes: crate::scene::scene_changes(scene),
        }
    }
}

/// Everything one drop produced.
#[derive(Debug, Clone)]
pub struct DropReport {
    /// What the drop was asked to do.
    pub inputs: DropInputs,
    /// Streamed measurements (peaks, impacts, whirl, window statistics).
    pub features: Features,
    /// The energy audit.
    pub energy: EnergyAudit,
    /// Integrator work counters.
    pub stats: Stats,
    /// Simulated time reached (s).
    pub end_time_s: f64,
    /// Why the run ended.
    pub stop_reason: StopReason,
    /// The orbit, when asked for.
    pub orbit: Option<Orbit>,
    /// Stable hash of the scene (16 hex digits).
    pub scene_hash: String,
    /// The state at the end (layout in [`crate::model::ix`]).
    pub final_state: [f64; N],
    /// Temperatures, thermal load and heat, when the scene carries a thermal model.
    pub thermal: Option<ThermalReport>,
    /// Ball loads, contact pressure and fatigue of the touchdown bearing, when the scene
    /// asks for the bearing analysis ([`crate::bearing`]).
    pub bearing: Option<BearingReport>,
    /// The orbit class, whether it settled, and why ([`crate::classify`](mod@crate::classify)).
    pub verdict: Verdict,
    /// How far the run was extended past its duration to let the class settle (s); 0 when
    /// it settled (or stopped) by then.
    pub extension_s: f64,
}

/// Why the drop's observer halted the integration.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Halt {
    /// The monitor's whirl stopping rule decided.
    WhirlDecided,
    /// The rotor spin fell below the stop speed.
    StopSpeed,
    /// The thermal network advanced over a macro-step end: the thermal load must be updated
    /// before the run goes on.
    ThermalSync,
}

/// Passes every step to an extra observer, then to the monitor, which may stop the run, as
/// may the coast-down's stop speed; then advances the thermal network over every macro-step
/// end the step passed. At each jump it books the switch's energy and tells the monitor.
struct Tap<'a, O> {
    extra: &'a mut O,
    mon: Monitor,
    /// Stop once |omega_r| falls below this (rad/s); 0 for never.
    stop_speed_rad_s: f64,
    /// The macro-step coupling, when the scene has a thermal model.
    thermal: Option<ThermalRun>,
    /// The touchdown bearing analysis, when the scene asks for it: it reads the race's
    /// displacement, spin and support force at every step's end.
    bearing: Option<BearingAnalysis>,
    /// Mechanical energy lost at mode switches (J): the elastic energy of a contact opened
    /// while still overlapping, booked with the damping loss.
    switch_loss_j: f64,
}

impl<O: Observer<DropSystem, N>> Observer<DropSystem, N> for Tap<'_, O> {
    type Halt = Halt;
    fn on_step(&mut self, sys: &DropSystem, step: &StepView<'_, N>) -> ControlFlow<Halt> {
        let _ = self.extra.on_step(sys, step);
        if let Some(b) = self.bearing.as_mut() {
            let (t1, y1) = (step.dense.t1(), step.dense.y1());
            let support_n = sys.with_forces(&y1, |f| f.support_n);
            b.observe_with_force(t1, y1[ix::XB], y1[ix::YB], y1[ix::WB], support_n);
        }
        if let ControlFlow::Break(WhirlDecided) = self.mon.on_step(sys, step) {
            return ControlFlow::Break(Halt::WhirlDecided);
        }
        if self.stop_speed_rad_s > 0.0 && step.dense.y1()[ix::WR].abs() < self.stop_speed_rad_s {
            return ControlFlow::Break(Halt::StopSpeed);
        }
        if let Some(th) = self.thermal.as_mut() {
            // Macro-step ends are met on the step's interpolant, so the dynamic steps are not
            // cut at them (a cut leaves a tiny last step that resets the step-size
            // controller); the new F_th takes effect from this step's end.
            let t1 = step.dense.t1();
            let mut synced = false;
            while th.next_boundary() <= t1 {
                let tb = th.next_boundary();
                th.advance(tb, &step.dense.eval(tb));
                synced = true;
            }
            if synced {
                return ControlFlow::Break(Halt::ThermalSync);
            }
        }
        ControlFlow::Continue(())
    }
}

impl<O: Observer<DropSystem, N>> HybridObserver<DropSystem, N> for Tap<'_, O> {
    fn on_jump(&mut self, sys: &DropSystem, t: f64, y: &[f64; N], from: Mode, to: Mode) {
        self.switch_loss_j += sys.mechanical_energy(y, from) - sys.mechanical_energy(y, to);
        if from.contact != to.contact {
            self.mon.contact_switch(t, to.contact);
        }
        self.mon.mode_switched();
    }
}

/// How the drop's event loop treats jumps: the scene's event budget, and a first step after
/// a switch of at most [`STEP_AFTER_SWITCH_S`].
pub(crate) fn jump_rules(scene: &Scene) -> JumpRules {
    JumpRules {
        max_events: scene.solver.max_events,
        step_after_jump_s: STEP_AFTER_SWITCH_S,
    }
}

/// Per-component absolute tolerances: displacements to `rtol * position_scale_m`, speeds and
/// energies to scales of the problem (impact speed sqrt(2 g s), spin, drop energy).
pub(crate) fn tolerances(scene: &Scene, sys: &DropSystem) -> StepControl<N> {
    let s = &scene.solver;
    let rtol = s.rtol;
    let pos = rtol * s.position_scale_m;
    let v_ref = (2.0 * scene.gravity_m_s2.max(1.0) * scene.clearance_m).sqrt();
    let vel = rtol * v_ref * 1e-2;
    let ang = rtol * 1e-3;
    let w = rtol * 1e-2;
    let en = rtol * (sys.weight_n() * scene.clearance_m).max(1e-9) * 1e-2;
    let mut atol = [0.0; N];
    for i in [ix::XR, ix::YR, ix::XB, ix::YB] {
        atol[i] = pos;
    }
    for i in [ix::TR, ix::TB] {
        atol[i] = ang;
    }
    for i in [ix::VXR, ix::VYR, ix::VXB, ix::VYB] {
        atol[i] = vel;
    }
    for i in [ix::WR, ix::WB] {
        atol[i] = w;
    }
    for i in [ix::XB, ix::YB, ix::VXB, ix::VYB] {
        atol[i] *= s.race_atol_scale;
    }
    for i in [ix::E_FRIC, ix::E_DAMP, ix::E_DRAG] {
        atol[i] = en;
    }
    StepControl {
        rtol,
        atol,
        h_min: s.min_step_s,
        max_attempts: s.max_step_attempts,
        fixed_step: None,
    }
}

/// The scene's optional release state (offset, velocity, race spin) on top of the default
/// release (rotor at the centre at rest, race at rest at its static sag). All zero by default,
/// so the state is then exactly the release of docs/model.md#release-state.
fn apply_release(scene: &Scene, y: &mut [f64; N]) {
    y[ix::XR] += scene.release_offset_m[0];
    y[ix::YR] += scene.release_offset_m[1];
    y[ix::VXR] += scene.release_velocity_m_s[0];
    y[ix::VYR] += scene.release_velocity_m_s[1];
    y[ix::WB] += scene.race_speed_rad_s;
}

/// Simulates one drop of `scene` under `opts`.
pub fn simulate(scene: &Scene, opts: &DropOptions) -> Result<DropReport, SolveError> {
    simulate_observed(scene, opts, &mut NoObserver)
}

/// [`simulate`], also showing every accepted step (with the system in its current mode) to
/// `extra`: for diagnostics and invariant checks along a run. `extra` cannot stop the run.
pub fn simulate_observed<O: Observer<DropSystem, N>>(
    scene: &Scene,
    opts: &DropOptions,
    extra: &mut O,
) -> Result<DropReport, SolveError> {
    scene.validate()?;
    opts.validate()?;
    let sys = DropSystem::new(scene);
    let ctl = tolerances(scene, &sys);
    let bdf_max = scene.solver.bdf_max_order as usize;
    match scene.solver.method {
        Method::Dopri5 => run_with(scene, opts, extra, sys, Dopri5::new(ctl)),
        Method::Dop853 => run_with(scene, opts, extra, sys, Dop853::new(ctl)),
        Method::Ros34pw2 => run_with(scene, opts, extra, sys, Ros34pw2::new(ctl)),
        Method::Rodas4 => run_with(scene, opts, extra, sys, Rodas4::new(ctl)),
        Method::Rodas5p => run_with(scene, opts, extra, sys, Rodas5p::new(ctl)),
        Method::Radau5 => run_with(scene, opts, extra, sys, crate::ode::Radau5::new(ctl)),
        Method::Bdf => {
            let st = crate::ode::Bdf::new(ctl).with_max_order(bdf_max);
            run_with(scene, opts, extra, sys, st)
        }
        Method::Rodas4Bdf => {
            let st = crate::ode::Rodas4Bdf::new(ctl).with_max_order(bdf_max);
            run_with(scene, opts, extra, sys, st)
        }
        Method::Rodas4Ndf => {
            let st = crate::ode::Rodas4Bdf::with_formula(ctl, crate::ode::Formula::Ndf)
                .with_max_order(bdf_max);
            run_with(scene, opts, extra, sys, st)
        }
    }
}

/// The drop loop for one stepper type.
fn run_with<O: Observer<DropSystem, N>, M: Stepper<N>>(
    scene: &Scene,
    opts: &DropOptions,
    extra: &mut O,
    mut sys: DropSystem,
    mut stepper: M,
) -> Result<DropReport, SolveError> {
    let mut y = sys.initial_state(scene.spin_rad_s());
    apply_release(scene, &mut y);
    let e0 = sys.mechanical_energy(&y, sys.mode);
    let cls = &scene.classification;
    let mut mon = Monitor::new(
        opts.duration_s,
        cls.window_s,
        opts.impact_merge_s,
        scene.spin_rad_s(),
        scene.clearance_m,
        scene.whirl_stop_turns,
        cls.min_duty,
        opts.orbit_points,
    );
    // A run not settled at its duration goes on in steps of half a window, up to the cap.
    let extension_step_s = 0.5 * cls.window_s;
    let end_cap_s = opts.duration_s + cls.max_extension_s;
    let mut t_end = opts.duration_s;
    mon.start(&sys, &y);
    // The thermal model, if asked for: the dynamics then run in macro steps (crate::thermal).
    let thermal = match &scene.thermal {
        Some(p) => Some(ThermalRun::new(scene, p, opts.duration_s, &y)?),
        None => None,
    };
    let bearing = match scene.bearing_as_run() {
        Some(pair) => Some(BearingAnalysis::new(&pair)?),
        None => None,
    };
    let mut tap = Tap {
        extra,
        mon,
        stop_speed_rad_s: scene.stop_speed_rpm.unwrap_or(0.0) * std::f64::consts::PI / 30.0,
        thermal,
        bearing,
        switch_loss_j: 0.0,
    };
    let rules = jump_rules(scene);
    let mut t = 0.0;
    let stop_reason = loop {
        match run_hybrid(
            &mut sys,
            &mut stepper,
            &mut t,
            &mut y,
            t_end,
            &mut tap,
            &rules,
        )? {
            Finish::EndTime => {
                let settled =
                    classify(&tap.mon.features(t, &y), StopReason::DurationReached, cls).settled;
                if settled || t_end >= end_cap_s {
                    break StopReason::DurationReached;
                }
                // A run shorter than the window goes straight to its length.
                t_end = (t_end + extension_step_s).max(cls.window_s).min(end_cap_s);
                stepper.keep_history_at_next_restart();
            }
            Finish::Halted(Halt::StopSpeed) => break StopReason::StopSpeedReached,
            Finish::Halted(Halt::ThermalSync) => {
                // The network advanced: F_th (eq. 30) for the next macro step (eq. 31).
                if let Some(th) = tap.thermal.as_ref() {
                    sys.thermal_load_n = th.load_n();
                }
                // The same state and mode, the drag's load a step further on: a stepper with
                // a history keeps it (the BDF of `rodas4_bdf`).
                stepper.keep_history_at_next_restart();
            }
            Finish::Halted(Halt::WhirlDecided) => break StopReason::WhirlDecided,
        }
    };
    let Tap {
        mon,
        thermal,
        bearing,
        switch_loss_j: switch_loss,
        ..
    } = tap;
    if y.iter().any(|v| !v.is_finite()) {
        return Err(SolveError::NonFiniteState { t_s: t });
    }
    let e1 = sys.mechanical_energy(&y, sys.mode);
    let (fric, damp, drag) = (y[ix::E_FRIC], y[ix::E_DAMP] + switch_loss, y[ix::E_DRAG]);
    let drop_energy_j = sys.weight_n() * scene.clearance_m;
    let energy = EnergyAudit::new(e0, e1, fric, damp, drag, drop_energy_j);
    if !(energy.residual_rel <= AUDIT_THRESHOLD) {
        return Err(SolveError::EnergyAudit {
            t_s: t,
            residual_rel: energy.residual_rel,
            threshold: AUDIT_THRESHOLD,
            initial_j: e0,
            final_j: e1,
            losses_j: fric + damp + drag,
        });
    }
    check_physical(&sys, &y, t)?;
    check_friction_heat(&energy, drop_energy_j, t)?;
    let (features, orbit) = mon.finish(&sys, t, &y);
    let verdict = classify(&features, stop_reason, cls);
    let thermal = thermal.map(|th| th.finish(t, &y));
    let bearing = bearing.map(BearingAnalysis::finish);
    Ok(DropReport {
        inputs: DropInputs::new(scene, opts.duration_s),
        features,
        energy,
        stats: stepper.stats(),
        end_time_s: t,
        stop_reason,
        orbit,
        scene_hash: scene.hash_hex(),
        final_state: y,
        thermal,
        bearing,
        verdict,
        extension_s: (t - opts.duration_s).max(0.0),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rotor more than the clearance beyond the race with the contact not acting, as a
    /// contact stepped over would leave it: the typed `unphysical` error. With the contact
    /// acting, or with the race's centre within the clearance, it passes.
    #[test]
    fn a_rotor_through_the_race_with_the_contact_open_is_unphysical() {
        let scene = Scene::paper();
        let mut sys = DropSystem::new(&scene);
        let s = sys.clearance_m();
        let mut y = [0.0; N];
        y[crate::model::ix::YR] = -3.0 * s;
        sys.mode.contact = false;
        match check_physical(&sys, &y, 0.5) {
            Err(e @ SolveError::Unphysical { .. }) => {
                assert!(e.to_string().contains("a contact was stepped over"), "{e}")
            }
            other => panic!("expected an unphysical error, got {other:?}"),
        }
        sys.mode.contact = true;
        assert!(check_physical(&sys, &y, 0.5).is_ok());
        sys.mode.contact = false;
        y[crate::model::ix::YR] = -0.5 * s;
        assert!(check_physical(&sys, &y, 0.5).is_ok());
    }

    #[test]
    fn the_audit_closes_without_overflow_and_fails_on_a_non_finite_energy() {
        // The usual case: the direct formula, bit for bit.
        let a = EnergyAudit::new(10.0, 4.0, 3.0, 2.0, 0.5, 0.01);
        assert_eq!(
            a.residual_rel,
            (10.0_f64 - 4.0 - (3.0 + 2.0 + 0.5)).abs() / 10.0
        );
        // Energies near the largest float: the sum would overflow to infinity (and the
        // residual to NaN or 0); scaled first, it closes.
        let big = 0.9 * f64::MAX;
        let a = EnergyAudit::new(big, 0.0, 0.5 * big, 0.5 * big, 0.0, 1.0);
        assert!(
            a.residual_rel.is_finite() && a.residual_rel < 1e-12,
            "{a:?}"
        );
        let a = EnergyAudit::new(big, 0.0, big, big, 0.0, 1.0);
        assert!((a.residual_rel - 0.5).abs() < 1e-12, "{a:?}");
        // An infinite or NaN energy fails the audit, whatever the others.
        for bad in [f64::INFINITY, f64::NAN] {
            let a = EnergyAudit::new(1.0, bad, 0.0, 0.0, 0.0, 1.0);
            assert_eq!(a.residual_rel, f64::INFINITY);
            assert!(!(a.residual_rel <= AUDIT_THRESHOLD));
            let a = EnergyAudit::new(1.0, 1.0, 0.0, 0.0, 0.0, bad);
            assert_eq!(a.residual_rel, f64::INFINITY);
        }
    }

    #[test]
    fn friction_that_made_energy_fails_even_when_the_books_balance() {
        // The wrong switch's drop without spin: the fall's 8.5 mJ, -1788 J of friction heat,
        // and the books balanced.
        let (e0, heat) = (-4.3e-8, -1788.0);
        let a = EnergyAudit::new(e0, e0 - heat - 0.5, heat, 0.5, 0.0, 8.5e-3);
        assert!(a.residual_rel < 1e-12, "{a:?}");
        match check_friction_heat(&a, 8.5e-3, 1.0) {
            Err(e @ SolveError::Unphysical { .. }) => {
                assert!(e.to_string().contains("friction made energy"), "{e}")
            }
            other => panic!("{other:?}"),
        }
        // A dip of integration error passes, in a spinning drop (scaled by its 1019 J) and in
        // one without spin (scaled by m g s); half the scale below zero does not.
        let a = EnergyAudit::new(1018.7, 1018.7 + 1e-6, -1e-6, 0.0, 0.0, 8.5e-3);
        assert!(check_friction_heat(&a, 8.5e-3, 1.0).is_ok());
        let a = EnergyAudit::new(0.0, -8.5e-3 + 1e-5, -1e-5, 8.5e-3, 0.0, 8.5e-3);
        assert!(check_friction_heat(&a, 8.5e-3, 1.0).is_ok());
        let a = EnergyAudit::new(0.0, -8.5e-3 + 1e-2, -1e-2, 8.5e-3, 0.0, 8.5e-3);
        assert!(check_friction_heat(&a, 8.5e-3, 1.0).is_err());
    }
}
