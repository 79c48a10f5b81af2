//! The thermal model of the paper's Secs. 2.3 and 3 (eqs. 14-31): bearing heat, the
//! seven-node heat network, thermal expansion, and the thermally induced load fed back into
//! the Palmgren drag torque.
//!
//! - [`heat`]: the split of the bearing's power loss into `H_i` and `H_o` (eqs. 15-16).
//! - [`network`]: eqs. 18-25 with Table 1's resistances, stepped exactly.
//! - [`expansion`]: eqs. 26-30.
//! - [`params`]: every material, geometry and coupling number, with its source.
//! - [`reference`](mod@reference): the fully coupled reference (network states inside the dynamic ODE).
//!
//! ## Two time scales
//! The contact moves on microseconds, the network on seconds to minutes. The drop is cut into
//! macro steps of `macro_step_s` (default 1 ms). Over each, the dynamics run with the thermal
//! load `F_th` frozen, and their heat is the exact integral the state already carries
//! (`E_FRIC` = the integral of `H_s`, `E_DRAG` = the integral of `M |omega_b|`). At the end of
//! the macro step the network advances over it exactly ([`network::ExactStep`]) with the heat
//! averaged over the step, and `F_th` is updated from the new temperatures for the next macro
//! step (eq. 31). The dynamic ODE keeps its 15 states: a drop without `thermal` carries no
//! thermal state and makes no thermal computation.

pub mod expansion;
pub mod heat;
pub mod network;
pub mod params;
pub mod reference;

use crate::error::InvalidParameter;
use crate::model::{ix, N};
use crate::scene::Scene;
use expansion::Expansion;
use heat::BearingHeatSplit;
use network::{ExactStep, Network, SceneGeometry, NODES};
pub use params::ThermalParams;
use serde::{Deserialize, Serialize};

/// The thermal model prepared for one scene: network, heat split and expansion.
#[derive(Debug, Clone, PartialEq)]
pub struct ThermalModel {
    /// The seven-node network.
    pub network: Network,
    /// The inner/outer split of the bearing heat.
    pub split: BearingHeatSplit,
    /// Expansion and induced load.
    pub expansion: Expansion,
    /// Ambient (and initial) temperature (K).
    pub ambient_k: f64,
    /// Macro step of the coupling (s).
    pub macro_step_s: f64,
}

impl ThermalModel {
    /// Builds the model for `scene` with parameters `p`, checking them against the scene's
    /// geometry and the heat network they make ([`Network::check_rates`]).
    pub fn new(scene: &Scene, p: &ThermalParams) -> Result<Self, InvalidParameter> {
        p.validate_with(scene.race_bore_radius_m(), scene.pitch_diameter_m)?;
        let g = SceneGeometry {
            rotor_radius_m: scene.rotor_radius_m(),
            race_bore_radius_m: scene.race_bore_radius_m(),
            pitch_diameter_m: scene.pitch_diameter_m,
            inner_race_mass_kg: scene.race_mass_kg,
        };
        let r_b = 0.5 * p.ball_diameter_m;
        let alpha0 = p.contact_angle_deg.to_radians();
        let network = Network::paper(p, &g);
        network.check_rates(p.macro_step_s)?;
        Ok(Self {
            network,
            split: BearingHeatSplit::new(p.ball_diameter_m, alpha0, scene.pitch_diameter_m),
            expansion: Expansion {
                xi_per_k: p.bearing_expansion_per_k,
                nu: p.bearing_poisson_ratio,
                r_s_m: g.race_bore_radius_m,
                r_i_m: 0.5 * scene.pitch_diameter_m - r_b,
                r_e_m: 0.5 * scene.pitch_diameter_m + r_b,
                r_o_m: 0.5 * p.outer_diameter_m,
                r_b_m: r_b,
                cos_alpha0: alpha0.cos(),
                k_n_per_m15: p
                    .induced_load_stiffness_n_per_m15
                    .unwrap_or(scene.support_stiffness_n_per_m_e),
                fit_m: p.fit_interference_m,
            },
            ambient_k: p.ambient_temperature_k,
            macro_step_s: p.macro_step_s,
        })
    }

    /// Node heat inputs (W) for rub heat `h_s` and bearing power loss `bearing_w` (W).
    pub fn heat_inputs(&self, h_s: f64, bearing_w: f64) -> [f64; NODES] {
        let (h_i, h_o) = self.split.split(bearing_w);
        self.network.heat_inputs(h_s, h_i, h_o)
    }
}

/// Final and peak temperature of one node (K).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FinalPeak {
    /// Temperature at the end of the run (K).
    #[serde(rename = "final")]
    pub final_k: f64,
    /// Highest temperature over the run, sampled at the macro-step ends (K).
    #[serde(rename = "peak")]
    pub peak_k: f64,
}

/// Final and peak temperature of every node (K), in the network's node order.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[allow(missing_docs)]
pub struct NodeTemperatures {
    pub rotor: FinalPeak,
    pub inner_race: FinalPeak,
    pub inner_lubricant: FinalPeak,
    pub balls: FinalPeak,
    pub outer_lubricant: FinalPeak,
    pub outer_race: FinalPeak,
    pub housing: FinalPeak,
}

impl NodeTemperatures {
    /// The seven nodes in [`network::node`] order.
    pub fn as_array(&self) -> [FinalPeak; NODES] {
        [
            self.rotor,
            self.inner_race,
            self.inner_lubricant,
            self.balls,
            self.outer_lubricant,
            self.outer_race,
            self.housing,
        ]
    }

    fn from_array(a: [FinalPeak; NODES]) -> Self {
        Self {
            rotor: a[0],
            inner_race: a[1],
            inner_lubricant: a[2],
            balls: a[3],
            outer_lubricant: a[4],
            outer_race: a[5],
            housing: a[6],
        }
    }

    /// The highest peak over all nodes (K).
    pub fn hottest_peak_k(&self) -> f64 {
        self.as_array()
            .iter()
            .map(|n| n.peak_k)
            .fold(f64::NEG_INFINITY, f64::max)
    }
}

/// The heat made during a drop (J), eq. 14's terms integrated, and where it went.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct HeatEnergies {
    /// Rotor-race rub heat, the integral of H_s (eq. 17).
    pub h_s_j: f64,
    /// Inner ball-race contact heat, the integral of H_i (eq. 15).
    pub h_i_j: f64,
    /// Outer ball-race contact heat, the integral of H_o (eq. 16).
    pub h_o_j: f64,
    /// Heat stored in the network at the end, `sum m C (T - T_inf)`.
    pub stored_j: f64,
    /// Heat lost to ambient over the run.
    pub lost_to_ambient_j: f64,
}

/// One sample of the temperature history (at a macro-step end).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ThermalSample {
    /// Time (s).
    pub t_s: f64,
    /// Node temperatures (K), in [`network::node`] order.
    pub temperatures_k: [f64; NODES],
    /// Thermally induced load F_th (N), eq. 30.
    pub load_n: f64,
    /// Heat power H = H_s + H_i + H_o (W), eq. 14, averaged over the macro step that ends
    /// here (0 at release).
    pub heat_w: f64,
}

/// What the thermal model reports for one drop.
#[derive(Debug, Clone, PartialEq)]
pub struct ThermalReport {
    /// Final and peak node temperatures (K).
    pub temperatures_k: NodeTemperatures,
    /// Peak thermally induced load F_th (N).
    pub peak_thermal_load_n: f64,
    /// F_th at the end (N).
    pub final_thermal_load_n: f64,
    /// Heat made and where it went.
    pub heat: HeatEnergies,
    /// Temperature history, decimated to at most about [`SERIES_POINTS`] samples.
    pub series: Vec<ThermalSample>,
    /// Network steps taken (one per macro step): the thermal part's work.
    pub network_steps: u64,
}

/// Largest number of samples kept in a temperature history.
pub const SERIES_POINTS: usize = 4000;

/// The macro-step coupling during one drop (see the module doc).
#[derive(Debug, Clone)]
pub struct ThermalRun {
    model: ThermalModel,
    step: ExactStep,
    dt_k: [f64; NODES],
    lost_j: f64,
    syncs: u64,
    t_last: f64,
    fric_last_j: f64,
    drag_last_j: f64,
    heat: HeatEnergies,
    peak_k: [f64; NODES],
    load_n: f64,
    peak_load_n: f64,
    series: Vec<ThermalSample>,
    stride: u64,
}

impl ThermalRun {
    /// Starts the coupling for a drop of `duration_s` at the release state `y0`.
    pub fn new(
        scene: &Scene,
        p: &ThermalParams,
        duration_s: f64,
        y0: &[f64; N],
    ) -> Result<Self, InvalidParameter> {
        let model = ThermalModel::new(scene, p)?;
        let step = ExactStep::new(&model.network, model.macro_step_s);
        if !step.is_finite() {
            // Not reached where `check_rates` passed; a last guard against NaN temperatures.
            return Err(InvalidParameter::new(
                "thermal network",
                "a step matrix with infinite or NaN entries",
                "parameters whose network the matrix exponential can step",
            ));
        }
        let macro_steps = (duration_s / model.macro_step_s).ceil();
        let stride = ((macro_steps / SERIES_POINTS as f64).ceil() as u64).max(1);
        let mut run = Self {
            step,
            dt_k: [0.0; NODES],
            lost_j: 0.0,
            syncs: 0,
            t_last: 0.0,
            fric_last_j: y0[ix::E_FRIC],
            drag_last_j: y0[ix::E_DRAG],
            heat: HeatEnergies {
                h_s_j: 0.0,
                h_i_j: 0.0,
                h_o_j: 0.0,
                stored_j: 0.0,
                lost_to_ambient_j: 0.0,
            },
            peak_k: [model.ambient_k; NODES],
            load_n: 0.0,
            peak_load_n: 0.0,
            series: Vec::new(),
            stride,
            model,
        };
        run.load_n = run.model.expansion.load_n(&run.dt_k);
        run.peak_load_n = run.load_n;
        run.record(0.0, 0.0);
        Ok(run)
    }

    /// The thermally induced load F_th for the coming macro step (N).
    pub fn load_n(&self) -> f64 {
        self.load_n
    }

    /// End of the current macro step (s).
    pub fn next_boundary(&self) -> f64 {
        ((self.syncs + 1) as f64) * self.model.macro_step_s
    }

    fn record(&mut self, t: f64, heat_w: f64) {
        let mut temps = self.dt_k;
        for v in temps.iter_mut() {
            *v += self.model.ambient_k;
        }
        self.series.push(ThermalSample {
            t_s: t,
            temperatures_k: temps,
            load_n: self.load_n,
            heat_w,
        });
    }

    /// Advances the network from the last sync to `t` with the heat the dynamics made in
    /// between (read from the energy accumulators of `y`), and returns the updated F_th (N).
    pub fn advance(&mut self, t: f64, y: &[f64; N]) -> f64 {
        let h = t - self.t_last;
        if h <= 0.0 {
            return self.load_n;
        }
        let e_s = y[ix::E_FRIC] - self.fric_last_j;
        let e_b = y[ix::E_DRAG] - self.drag_last_j;
        let (e_i, e_o) = self.model.split.split(e_b);
        let q = self.model.network.heat_inputs(e_s / h, e_i / h, e_o / h);
        if (h - self.step.h_s).abs() <= 1e-9 * self.step.h_s {
            self.step.advance(&mut self.dt_k, &mut self.lost_j, &q);
        } else {
            // A shorter last step (end of the run, or a stop inside a macro step).
            ExactStep::new(&self.model.network, h).advance(&mut self.dt_k, &mut self.lost_j, &q);
        }
        self.heat.h_s_j += e_s;
        self.heat.h_i_j += e_i;
        self.heat.h_o_j += e_o;
        self.fric_last_j = y[ix::E_FRIC];
        self.drag_last_j = y[ix::E_DRAG];
        self.t_last = t;
        self.syncs += 1;
        for (p, d) in self.peak_k.iter_mut().zip(self.dt_k) {
            *p = p.max(self.model.ambient_k + d);
        }
        self.load_n = self.model.expansion.load_n(&self.dt_k);
        self.peak_load_n = self.peak_load_n.max(self.load_n);
        if self.syncs.is_multiple_of(self.stride) {
            self.record(t, (e_s + e_b) / h);
        }
        self.load_n
    }

    /// Closes the run at `t` (advancing over a last partial macro step) and reports.
    pub fn finish(mut self, t: f64, y: &[f64; N]) -> ThermalReport {
        let (fric, drag, t_last) = (self.fric_last_j, self.drag_last_j, self.t_last);
        self.advance(t, y);
        if self.series.last().is_none_or(|s| s.t_s < t) {
            let h = t - t_last;
            let heat = if h > 0.0 {
                (y[ix::E_FRIC] - fric + y[ix::E_DRAG] - drag) / h
            } else {
                0.0
            };
            self.record(t, heat);
        }
        let mut temps = [FinalPeak {
            final_k: 0.0,
            peak_k: 0.0,
        }; NODES];
        for k in 0..NODES {
            temps[k] = FinalPeak {
                final_k: self.model.ambient_k + self.dt_k[k],
                peak_k: self.peak_k[k],
            };
        }
        self.heat.stored_j = self.model.network.stored_j(&self.dt_k);
        self.heat.lost_to_ambient_j = self.lost_j;
        ThermalReport {
            temperatures_k: NodeTemperatures::from_array(temps),
            peak_thermal_load_n: self.peak_load_n,
            final_thermal_load_n: self.load_n,
            heat: self.heat,
            series: self.series,
            network_steps: self.syncs,
        }
    }
}
