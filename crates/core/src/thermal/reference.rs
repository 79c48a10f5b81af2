//! The fully coupled reference: the seven network temperatures integrated inside the dynamic
//! ODE at the contact step, with the thermal load F_th re-evaluated at every right-hand-side
//! evaluation from the current temperatures. It is what the macro-step coupling of
//! [`super::ThermalRun`] approximates, and is meant for tests on short cases: it pays the
//! contact step size for the network, which is what the macro step avoids.

use super::network::NODES;
use super::ThermalModel;
use crate::drop::{jump_rules, tolerances};
use crate::error::SolveError;
use crate::model::{ix, DropSystem, Guard, Mode, N};
use crate::ode::{
    run_hybrid, Dopri5, Finish, Hybrid, NoObserver, OdeSystem, Stats, StepControl, Stepper,
    MAX_GUARDS,
};
use crate::scene::Scene;

/// State size: the dynamic state, then the seven temperature rises (K).
const NC: usize = N + NODES;

/// The dynamic system with the network appended.
struct Coupled<'a> {
    sys: DropSystem,
    model: &'a ThermalModel,
}

impl Coupled<'_> {
    /// The dynamic system at the thermal load of the temperatures in `y`, and its state.
    fn loaded(&self, y: &[f64; NC]) -> (DropSystem, [f64; N]) {
        let mut yd = [0.0; N];
        yd.copy_from_slice(&y[..N]);
        let mut dt = [0.0; NODES];
        dt.copy_from_slice(&y[N..]);
        let mut s = self.sys.clone();
        s.thermal_load_n = self.model.expansion.load_n(&dt);
        (s, yd)
    }
}

impl OdeSystem<NC> for Coupled<'_> {
    type Guard = Guard;

    fn rhs(&self, t: f64, y: &[f64; NC], dy: &mut [f64; NC]) {
        let (s, yd) = self.loaded(y);
        let mut d = [0.0; N];
        s.rhs(t, &yd, &mut d);
        dy[..N].copy_from_slice(&d);
        let mut dt = [0.0; NODES];
        dt.copy_from_slice(&y[N..]);
        let q = self.model.heat_inputs(d[ix::E_FRIC], d[ix::E_DRAG]);
        dy[N..].copy_from_slice(&self.model.network.rates(&dt, &q));
    }

    fn guards(&self, t: f64, y: &[f64; NC], g: &mut [f64; MAX_GUARDS]) -> usize {
        let (s, yd) = self.loaded(y);
        s.guards(t, &yd, g)
    }

    fn max_step(&self) -> f64 {
        self.sys.max_step()
    }
}

/// The dynamic system's modes and jump map, at the thermal load of the temperatures.
impl Hybrid<NC> for Coupled<'_> {
    type Mode = Mode;
    fn mode(&self) -> Mode {
        self.sys.mode
    }
    fn set_mode(&mut self, mode: Mode) {
        self.sys.mode = mode;
    }
    fn jump(&self, guard: Guard, y: &[f64; NC]) -> Mode {
        let (s, yd) = self.loaded(y);
        s.jump(guard, &yd)
    }
}

/// What the reference run ends with.
#[derive(Debug, Clone, PartialEq)]
pub struct ReferenceResult {
    /// Node temperatures at the end (K).
    pub temperatures_k: [f64; NODES],
    /// Thermally induced load at the end (N).
    pub load_n: f64,
    /// Integral of H_s (J).
    pub h_s_j: f64,
    /// Integral of the bearing power H_i + H_o (J).
    pub bearing_j: f64,
    /// Integrator work.
    pub stats: Stats,
}

/// Runs `scene` (which must carry `thermal`) for `duration_s` fully coupled. Temperatures are
/// integrated with the dynamic tolerance, to `rtol * 1 mK` absolute.
pub fn simulate_fully_coupled(
    scene: &Scene,
    duration_s: f64,
) -> Result<ReferenceResult, SolveError> {
    scene.validate()?;
    let p = scene.thermal.as_ref().ok_or_else(|| {
        crate::error::InvalidParameter::new("thermal", "null", "a thermal parameter set")
    })?;
    let model = ThermalModel::new(scene, p)?;
    let mut sys = DropSystem::new(scene);
    let y0 = sys.initial_state(scene.spin_rad_s());
    let base = tolerances(scene, &sys);
    let mut atol = [scene.solver.rtol * 1e-3; NC];
    atol[..N].copy_from_slice(&base.atol);
    let mut stepper = Dopri5::new(StepControl {
        rtol: base.rtol,
        atol,
        h_min: base.h_min,
        max_attempts: base.max_attempts,
        fixed_step: None,
    });
    let mut y = [0.0; NC];
    y[..N].copy_from_slice(&y0);
    let mut c = Coupled { sys, model: &model };
    let mut t = 0.0;
    match run_hybrid(
        &mut c,
        &mut stepper,
        &mut t,
        &mut y,
        duration_s,
        &mut NoObserver,
        &jump_rules(scene),
    )? {
        Finish::EndTime => {}
        Finish::Halted(never) => match never {},
    }
    let mut dt = [0.0; NODES];
    dt.copy_from_slice(&y[N..]);
    let mut temps = dt;
    for v in temps.iter_mut() {
        *v += model.ambient_k;
    }
    Ok(ReferenceResult {
        temperatures_k: temps,
        load_n: model.expansion.load_n(&dt),
        h_s_j: y[ix::E_FRIC],
        bearing_j: y[ix::E_DRAG],
        stats: stepper.stats(),
    })
}
