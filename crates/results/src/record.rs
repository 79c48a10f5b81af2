//! The JSON record of one drop. Field names are a contract that later work and users rely on
//! (docs/results-format.md).

use serde::{Deserialize, Serialize};
use whirlmap_core::classify::{OrbitClass, Reason};
use whirlmap_core::ode::Stats;
use whirlmap_core::thermal::{HeatEnergies, NodeTemperatures};
use whirlmap_core::{DropInputs, DropReport, EnergyAudit, Features, StopReason, MODEL_VERSION};

/// One drop's outputs, as written by `whirlmap drop --json` and, per point, by sweeps.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DropRecord {
    /// What the drop was asked to do: speed, friction coefficient, duration and every scene
    /// field that differs from the paper's scene, so the record stands alone. Always written;
    /// absent only in records made before the records carried their inputs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inputs: Option<DropInputs>,
    /// Orbit class: the motion the rotor settled into
    /// ([`whirlmap_core::classify`](mod@whirlmap_core::classify)).
    pub class: OrbitClass,
    /// Why it got that class; for `unresolved`, why it had not settled at the cap.
    pub class_reason: Reason,
    /// Net turns of the contact point before the motion that decided the class (signed
    /// relative to the spin): a transient whirl that died out shows here.
    pub transient_whirl_turns: f64,
    /// Peak force of the first impact after free fall (N).
    pub first_contact_force_n: f64,
    /// Maximum rotor-race contact force over the run (N).
    pub max_contact_force_n: f64,
    /// Peak friction power H_s (W), eq. 17.
    pub peak_friction_power_w: f64,
    /// Peak heat power H = H_s + bearing drag power (W).
    pub peak_heat_power_w: f64,
    /// Whirl frequency (Hz), signed: negative is opposite to the spin.
    pub whirl_frequency_hz: f64,
    /// Fraction of the classification window with the contact active.
    pub contact_duty: f64,
    /// Impacts (contact episodes, merged within 0.5 ms).
    pub impacts: u64,
    /// Simulated time reached (s): when the class was decided, or the extension cap.
    pub end_time_s: f64,
    /// How far the run was extended past its duration to let the class settle (s).
    pub extension_s: f64,
    /// Why the run ended.
    pub stop_reason: StopReason,
    /// The energy audit.
    pub energy: EnergyAudit,
    /// Integrator work counters.
    pub stats: Stats,
    /// Stable hash of the scene.
    pub scene_hash: String,
    /// Model version the record was made with.
    pub model_version: u32,
    /// Every streamed feature (for diagnostics and re-classification).
    pub features: Features,
    /// Final and peak temperature per network node (K); only with the thermal model (absent
    /// otherwise, so records without it are unchanged).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub temperatures_k: Option<NodeTemperatures>,
    /// Peak thermally induced bearing load F_th (N), eq. 30; only with the thermal model.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thermal_load_n: Option<f64>,
    /// Heat made (H_s, H_i, H_o integrated, J) and where it went; only with the thermal model.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub heat: Option<HeatEnergies>,
    /// Peak load on one ball of the touchdown bearing pair (N); only with the bearing
    /// analysis (absent otherwise, so records without it are unchanged).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peak_ball_load_n: Option<f64>,
    /// Peak Hertz contact pressure of the most loaded ball, inner or outer race (Pa); only
    /// with the bearing analysis.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peak_contact_pressure_pa: Option<f64>,
    /// The static limit (4.2 GPa, ISO 76) over the peak contact pressure; below 1 the drop
    /// brinells the races. Only with the bearing analysis.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub static_safety_factor: Option<f64>,
    /// Palmgren-Miner fatigue damage of the inner race from this drop (ISO 281 load-life,
    /// L10 sense); only with the bearing analysis. A whirl run stopped after
    /// `whirl_stop_turns` turns gives the damage of those turns only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damage_per_drop: Option<f64>,
    /// Drops of this kind to fatigue failure (1 / damage, L10 sense); only with the bearing
    /// analysis.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drops_to_failure: Option<f64>,
}

impl DropRecord {
    /// Builds the record of a finished drop.
    pub fn from_report(r: &DropReport) -> Self {
        let f = &r.features;
        Self {
            inputs: Some(r.inputs.clone()),
            class: r.verdict.class,
            class_reason: r.verdict.reason,
            transient_whirl_turns: f.transient_whirl_turns,
            first_contact_force_n: f.first_contact_force_n,
            max_contact_force_n: f.max_contact_force_n,
            peak_friction_power_w: f.peak_friction_power_w,
            peak_heat_power_w: f.peak_heat_power_w,
            whirl_frequency_hz: f.whirl_frequency_hz,
            contact_duty: f.window.stats.contact_duty,
            impacts: f.impacts,
            end_time_s: r.end_time_s,
            extension_s: r.extension_s,
            stop_reason: r.stop_reason,
            energy: r.energy,
            stats: r.stats,
            scene_hash: r.scene_hash.clone(),
            model_version: MODEL_VERSION,
            features: r.features,
            temperatures_k: r.thermal.as_ref().map(|t| t.temperatures_k),
            thermal_load_n: r.thermal.as_ref().map(|t| t.peak_thermal_load_n),
            heat: r.thermal.as_ref().map(|t| t.heat),
            peak_ball_load_n: r.bearing.as_ref().map(|b| b.peak_ball_load_n),
            peak_contact_pressure_pa: r.bearing.as_ref().map(|b| b.peak_contact_pressure_pa),
            static_safety_factor: r.bearing.as_ref().map(|b| b.static_safety_factor),
            damage_per_drop: r.bearing.as_ref().map(|b| b.damage_per_drop),
            drops_to_failure: r.bearing.as_ref().map(|b| b.drops_to_failure),
        }
    }
}
