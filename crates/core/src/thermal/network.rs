//! The seven-node heat network of the paper's Sec. 3.1, eqs. 18-25, with Table 1's thermal
//! resistances, and its exact step over an interval of constant heat input.
//!
//! Nodes ([`node`]): rotor `s`, inner race `i`, inner lubricant `Li`, balls `b`, outer lubricant
//! `Le`, outer race `o`, housing `h`; ambient `T_inf`. Each node obeys eq. 18,
//! `m C dT/dt = sum of heat flows`, on the temperature rise `dT = T - T_inf`.
//!
//! How the printed equations are resolved (they are not an energy-conserving network as
//! printed, and two resistances are undefined):
//! - **R_1 and R_2** (eqs. 20-24) are the ball-side resistances of the inner and the outer
//!   contact: the lubricant film of Table 1 in series with the balls' own conduction,
//!   `R_1 = R_Li + R_b` and `R_2 = R_Le + R_b`.
//! - **A conservative network.** Printed eq. 20 drains the inner race into the balls through
//!   `R_i + R_1`, but eq. 22 has no matching inflow, and eq. 21 links the inner lubricant to the
//!   inner race through `R_i` with no matching term in eq. 20 (likewise eqs. 23-24 at the outer
//!   side). Every link must appear in both its nodes' equations or heat is created or lost. We
//!   keep the chain the resistances describe: race `i` --R_i-- lubricant `Li` --R_1-- balls
//!   `b` --R_2-- lubricant `Le` --R_e-- race `o`; eq. 20's `R_i + R_1` is exactly this path
//!   with the lubricant node in between (as eq. 21 has it). Hence `R_o` of eqs. 23-24 is
//!   Table 1's `R_e`.
//! - The other links are as printed: rotor-inner race `R_sr`; rotor-ambient `R_sac + R_sav`
//!   (conduction along the journal, then convection at its end, eq. 19); balls-ambient `R_La`
//!   (eq. 22); outer race-housing `R_hrc || R_hac` (eq. 24); housing-ambient `R_hrv || R_hav`
//!   (eq. 25).
//! - **Heat inputs.** `H_r` of eqs. 19-20 is eq. 17's `H_s`, half to the rotor and half to the
//!   inner race (a parameter). The printed shares of `H_i` (inner race, inner lubricant and
//!   balls each `H_i/2`) sum to 1.5 `H_i`; we give the lubricant node a share (default 1/3) and
//!   split the rest equally between race and balls, and the same at the outer contact.
//! - Radii: `r_s` is the rotor journal radius in `R_sac`, `R_sav`; in `R_i` the inner race
//!   conducts from its bore (the rotor's radius plus the touchdown clearance) to its raceway
//!   `r_i = d_m/2 - r_b`; the outer race from its raceway `r_e = d_m/2 + r_b` to `r_o = D/2`.
//!   Table 1's `n` in `R_Li`, `R_Le` is the ball count `z`.

use super::params::ThermalParams;
use crate::error::InvalidParameter;
use std::f64::consts::PI;

/// Node indices of the network.
pub mod node {
    /// Rotor (shaft) journal, eq. 19.
    pub const ROTOR: usize = 0;
    /// Inner race, eq. 20.
    pub const INNER_RACE: usize = 1;
    /// Lubricant at the inner contact, eq. 21.
    pub const INNER_LUBRICANT: usize = 2;
    /// Balls, eq. 22.
    pub const BALLS: usize = 3;
    /// Lubricant at the outer contact, eq. 23.
    pub const OUTER_LUBRICANT: usize = 4;
    /// Outer race, eq. 24.
    pub const OUTER_RACE: usize = 5;
    /// Housing, eq. 25.
    pub const HOUSING: usize = 6;
    /// Node names as used in records and charts.
    pub const NAMES: [&str; 7] = [
        "rotor",
        "inner_race",
        "inner_lubricant",
        "balls",
        "outer_lubricant",
        "outer_race",
        "housing",
    ];
}

/// Number of network nodes.
pub const NODES: usize = 7;

/// The largest rate times step [`Network::check_rates`] lets through: at the default
/// parameters the fastest node's is about 0.02 (1 ms steps), so this leaves
/// room for every bearing; the matrix exponential takes about `log2` of it squarings.
pub const MAX_RATE_TIMES_STEP: f64 = 1e6;

/// Table 1's thermal resistances (K/W) at a parameter set, plus the resolved `R_1`, `R_2`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(non_snake_case, missing_docs)]
pub struct Resistances {
    pub R_i: f64,
    pub R_e: f64,
    pub R_sac: f64,
    pub R_sav: f64,
    pub R_sr: f64,
    pub R_hac: f64,
    pub R_hav: f64,
    pub R_hrc: f64,
    pub R_hrv: f64,
    pub R_b: f64,
    pub R_Li: f64,
    pub R_Le: f64,
    pub R_La: f64,
    /// `R_Li + R_b` (eqs. 20-22).
    pub R_1: f64,
    /// `R_Le + R_b` (eqs. 22-24).
    pub R_2: f64,
}

/// Geometry the network takes from the dynamic scene (m, kg).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SceneGeometry {
    /// Rotor journal radius r_s.
    pub rotor_radius_m: f64,
    /// Inner race bore radius (rotor radius plus clearance).
    pub race_bore_radius_m: f64,
    /// Bearing pitch diameter d_m.
    pub pitch_diameter_m: f64,
    /// Inner race mass m_i (Table 2).
    pub inner_race_mass_kg: f64,
}

impl Resistances {
    /// Table 1 at `p` and the scene geometry `g`.
    pub fn new(p: &ThermalParams, g: &SceneGeometry) -> Self {
        let r_s = g.rotor_radius_m;
        let r_bore = g.race_bore_radius_m;
        let r_b = 0.5 * p.ball_diameter_m;
        let r_i = 0.5 * g.pitch_diameter_m - r_b;
        let r_e = 0.5 * g.pitch_diameter_m + r_b;
        let r_o = 0.5 * p.outer_diameter_m;
        let r_h = p.housing_outer_radius_m;
        let w = p.bearing_width_m;
        let z = p.ball_count as f64;
        let (lam_b, lam_s, lam_h, lam_l) = (
            p.bearing_conductivity_w_m_k,
            p.rotor_conductivity_w_m_k,
            p.housing_conductivity_w_m_k,
            p.lubricant_conductivity_w_m_k,
        );
        let l_h = p.housing_length_m;
        let ring = r_h * r_h - r_o * r_o;
        let r_b_res = 1.0 / (z * lam_b * PI * r_b);
        let r_li = r_b / (lam_l * (2.0 * PI * r_i * w - z * PI * r_b * r_b));
        let r_le = r_b / (lam_l * (2.0 * PI * r_e * w - z * PI * r_b * r_b));
        Self {
            R_i: (r_i / r_bore).ln() / (2.0 * PI * lam_b * w),
            R_e: (r_o / r_e).ln() / (2.0 * PI * lam_b * w),
            R_sac: p.rotor_node_length_m / (lam_s * PI * r_s * r_s),
            R_sav: 1.0 / (p.rotor_convection_w_m2_k * PI * r_s * r_s),
            R_sr: 1.0 / (lam_s * PI * w),
            R_hac: l_h / (2.0 * PI * lam_h * ring),
            R_hav: 1.0 / (PI * p.housing_convection_w_m2_k * ring),
            R_hrc: (r_h / r_o).ln() / (2.0 * PI * lam_h * l_h),
            R_hrv: 1.0 / (2.0 * PI * r_h * l_h * p.housing_convection_w_m2_k),
            R_b: r_b_res,
            R_Li: r_li,
            R_Le: r_le,
            R_La: 1.0 / (p.lubricant_convection_w_m2_k * PI * (r_e * r_e - r_i * r_i)),
            R_1: r_li + r_b_res,
            R_2: r_le + r_b_res,
        }
    }
}

/// Parallel combination; an infinite resistance (zero convection) drops out.
fn parallel(a: f64, b: f64) -> f64 {
    1.0 / (1.0 / a + 1.0 / b)
}

/// A linear heat network `C dT/dt = q - G dT` on temperature rises over ambient: node heat
/// capacities, symmetric links and links to ambient (all as conductances, W/K).
#[derive(Debug, Clone, PartialEq)]
pub struct Network {
    /// Heat capacity `m C` of each node (J/K), eq. 18.
    pub capacity_j_k: [f64; NODES],
    /// Links `(a, b, conductance W/K)`; each acts on both of its nodes.
    pub links: Vec<(usize, usize, f64)>,
    /// Conductance from each node to ambient (W/K); 0 for none.
    pub ambient_w_k: [f64; NODES],
    /// Share of `H_s` into the rotor node (the rest into the inner race).
    pub rub_heat_to_rotor: f64,
    /// Share of `H_i` (`H_o`) into the inner (outer) lubricant node.
    pub contact_heat_to_lubricant: f64,
}

impl Network {
    /// The paper's seven-node network (eqs. 19-25 as resolved in the module doc).
    pub fn paper(p: &ThermalParams, g: &SceneGeometry) -> Self {
        use node::*;
        let r = Resistances::new(p, g);
        let r_b = 0.5 * p.ball_diameter_m;
        let r_o = 0.5 * p.outer_diameter_m;
        let ball_mass =
            p.ball_count as f64 * p.bearing_density_kg_m3 * 4.0 / 3.0 * PI * r_b.powi(3);
        let rotor_mass =
            p.rotor_density_kg_m3 * PI * g.rotor_radius_m.powi(2) * p.rotor_node_length_m;
        let housing_mass = p.housing_density_kg_m3
            * PI
            * (p.housing_outer_radius_m.powi(2) - r_o * r_o)
            * p.housing_length_m;
        let c_b = p.bearing_specific_heat_j_kg_k;
        let c_l = p.lubricant_specific_heat_j_kg_k * p.lubricant_mass_kg;
        let mut capacity = [0.0; NODES];
        capacity[ROTOR] = rotor_mass * p.rotor_specific_heat_j_kg_k;
        capacity[INNER_RACE] = g.inner_race_mass_kg * c_b;
        capacity[INNER_LUBRICANT] = c_l;
        capacity[BALLS] = ball_mass * c_b;
        capacity[OUTER_LUBRICANT] = c_l;
        capacity[OUTER_RACE] = p.outer_race_mass_kg * c_b;
        capacity[HOUSING] = housing_mass * p.housing_specific_heat_j_kg_k;
        let mut ambient = [0.0; NODES];
        // Zero convection gives an infinite resistance: 1 / inf = 0, no link.
        ambient[ROTOR] = 1.0 / (r.R_sac + r.R_sav);
        ambient[BALLS] = 1.0 / r.R_La;
        ambient[HOUSING] = 1.0 / parallel(r.R_hrv, r.R_hav);
        Self {
            capacity_j_k: capacity,
            links: vec![
                (ROTOR, INNER_RACE, 1.0 / r.R_sr),
                (INNER_RACE, INNER_LUBRICANT, 1.0 / r.R_i),
                (INNER_LUBRICANT, BALLS, 1.0 / r.R_1),
                (BALLS, OUTER_LUBRICANT, 1.0 / r.R_2),
                (OUTER_LUBRICANT, OUTER_RACE, 1.0 / r.R_e),
                (OUTER_RACE, HOUSING, 1.0 / parallel(r.R_hrc, r.R_hac)),
            ],
            ambient_w_k: ambient,
            rub_heat_to_rotor: p.rub_heat_to_rotor,
            contact_heat_to_lubricant: p.contact_heat_to_lubricant,
        }
    }

    /// Heat input per node (W) from the rub heat `H_s` and the contact heats `H_i`, `H_o`
    /// (eqs. 19-24 as resolved): the shares always sum to `H_s + H_i + H_o`.
    pub fn heat_inputs(&self, h_s: f64, h_i: f64, h_o: f64) -> [f64; NODES] {
        use node::*;
        let fl = self.contact_heat_to_lubricant;
        let to_rotor = self.rub_heat_to_rotor * h_s;
        let mut q = [0.0; NODES];
        q[ROTOR] = to_rotor;
        q[INNER_RACE] = (h_s - to_rotor) + 0.5 * (1.0 - fl) * h_i;
        q[INNER_LUBRICANT] = fl * h_i;
        q[BALLS] = 0.5 * (1.0 - fl) * (h_i + h_o);
        q[OUTER_LUBRICANT] = fl * h_o;
        q[OUTER_RACE] = 0.5 * (1.0 - fl) * h_o;
        q
    }

    /// Checks that the network can be stepped exactly over `macro_step_s`: every heat
    /// capacity positive and finite, every conductance finite and not negative, and at each
    /// node the rate of its fastest exchange, its conductances over its capacity, times the
    /// step at most [`MAX_RATE_TIMES_STEP`]; the error names the node that fails worst. Parameters inside their own ranges can still
    /// combine past that (a lubricant film of almost no area, a housing of almost no
    /// length): the matrix exponential then overflows, or never ends its squarings.
    pub fn check_rates(&self, macro_step_s: f64) -> Result<(), InvalidParameter> {
        let mut exchange_w_k = self.ambient_w_k;
        for &(a, b, c) in &self.links {
            exchange_w_k[a] += c;
            exchange_w_k[b] += c;
        }
        let links_ok = self.links.iter().all(|l| l.2.is_finite() && l.2 >= 0.0)
            && self.ambient_w_k.iter().all(|g| g.is_finite() && *g >= 0.0);
        // Each node's rate, a capacity that is not positive and finite (or a NaN) counting
        // as infinitely fast; the worst node is the one reported.
        let rate = |k: usize| {
            let cap = self.capacity_j_k[k];
            let r = exchange_w_k[k] / cap;
            if cap > 0.0 && cap.is_finite() && !r.is_nan() {
                r
            } else {
                f64::INFINITY
            }
        };
        let k = (0..NODES).fold(0, |w, k| if rate(k) > rate(w) { k } else { w });
        let rate_times_step = rate(k) * macro_step_s;
        if !(links_ok && rate_times_step <= MAX_RATE_TIMES_STEP) {
            return Err(InvalidParameter::new(
                &format!("thermal network, node {}", node::NAMES[k]),
                format!(
                    "{} J/K of heat capacity against {} W/K of conductance (its rate times \
                     thermal.macro_step_s: {})",
                    crate::scene::approx(self.capacity_j_k[k]),
                    crate::scene::approx(exchange_w_k[k]),
                    crate::scene::approx(rate_times_step)
                ),
                &format!(
                    "a positive, finite heat capacity and a rate times the step <= \
                     {MAX_RATE_TIMES_STEP:e}: a heat capacity (a mass, density or specific \
                     heat) far too small, or a conductance (a conductivity, or a length or \
                     film area near zero) far too large for a bearing"
                ),
            ));
        }
        Ok(())
    }

    /// `G`: the conductance matrix (W/K), symmetric, ambient links on the diagonal.
    pub fn conductance_matrix(&self) -> [[f64; NODES]; NODES] {
        let mut g = [[0.0; NODES]; NODES];
        for &(a, b, c) in &self.links {
            g[a][a] += c;
            g[b][b] += c;
            g[a][b] -= c;
            g[b][a] -= c;
        }
        for (k, c) in self.ambient_w_k.iter().enumerate() {
            g[k][k] += c;
        }
        g
    }

    /// `d(dT)/dt = C^-1 (q - G dT)` (K/s), eqs. 19-25.
    pub fn rates(&self, dt_k: &[f64; NODES], q_w: &[f64; NODES]) -> [f64; NODES] {
        let mut flow = *q_w;
        for &(a, b, c) in &self.links {
            let f = c * (dt_k[a] - dt_k[b]);
            flow[a] -= f;
            flow[b] += f;
        }
        let mut out = [0.0; NODES];
        for k in 0..NODES {
            out[k] = (flow[k] - self.ambient_w_k[k] * dt_k[k]) / self.capacity_j_k[k];
        }
        out
    }

    /// Heat flowing to ambient (W) at temperature rises `dt_k`.
    pub fn loss_w(&self, dt_k: &[f64; NODES]) -> f64 {
        (0..NODES).map(|k| self.ambient_w_k[k] * dt_k[k]).sum()
    }

    /// Heat stored (J) at temperature rises `dt_k`: `sum m C dT`.
    pub fn stored_j(&self, dt_k: &[f64; NODES]) -> f64 {
        (0..NODES).map(|k| self.capacity_j_k[k] * dt_k[k]).sum()
    }
}

use nalgebra::{SMatrix, SVector};

/// Size of the augmented system of [`ExactStep`]: seven temperatures, the ambient-loss
/// accumulator, and seven constant heat inputs.
const AUG: usize = 2 * NODES + 1;

/// The network's exact step over `h` with constant heat input: `x(h) = Phi x(0) + Gamma q`,
/// where `x` is the seven temperature rises plus the heat lost to ambient (J). `Phi` and
/// `Gamma` are the blocks of `exp(h Z)` for the augmented matrix
/// `Z = [[-C^-1 G, 0, C^-1], [g_amb^T, 0, 0], [0, 0, 0]]` (Van Loan's construction), so the
/// step is exact for any `h`, however stiff the network, and the loss integral is exact too.
#[derive(Debug, Clone, PartialEq)]
pub struct ExactStep {
    /// The step (s).
    pub h_s: f64,
    phi: SMatrix<f64, { NODES + 1 }, { NODES + 1 }>,
    gamma: SMatrix<f64, { NODES + 1 }, NODES>,
}

impl ExactStep {
    /// Precomputes the step of `h_s` for `net`: nalgebra's matrix exponential (scaling and
    /// squaring with a Pade approximant) of the augmented matrix.
    pub fn new(net: &Network, h_s: f64) -> Self {
        let g = net.conductance_matrix();
        let mut z = SMatrix::<f64, AUG, AUG>::zeros();
        for a in 0..NODES {
            for b in 0..NODES {
                z[(a, b)] = -g[a][b] / net.capacity_j_k[a] * h_s;
            }
            z[(a, NODES + 1 + a)] = h_s / net.capacity_j_k[a];
            z[(NODES, a)] = net.ambient_w_k[a] * h_s;
        }
        let e = z.exp();
        Self {
            h_s,
            phi: e
                .fixed_view::<{ NODES + 1 }, { NODES + 1 }>(0, 0)
                .into_owned(),
            gamma: e
                .fixed_view::<{ NODES + 1 }, NODES>(0, NODES + 1)
                .into_owned(),
        }
    }

    /// Whether every entry of the step's matrices is finite.
    pub fn is_finite(&self) -> bool {
        self.phi
            .iter()
            .chain(self.gamma.iter())
            .all(|x| x.is_finite())
    }

    /// Advances temperature rises `dt_k` and the ambient loss `lost_j` over the step with
    /// constant heat input `q_w`.
    pub fn advance(&self, dt_k: &mut [f64; NODES], lost_j: &mut f64, q_w: &[f64; NODES]) {
        let mut x = SVector::<f64, { NODES + 1 }>::zeros();
        x.fixed_rows_mut::<NODES>(0).copy_from_slice(dt_k);
        x[NODES] = *lost_j;
        let out = self.phi * x + self.gamma * SVector::<f64, NODES>::from_column_slice(q_w);
        dt_k.copy_from_slice(&out.as_slice()[..NODES]);
        *lost_j = out[NODES];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::thermal::ThermalModel;
    use crate::Scene;

    /// The largest rate times step over the nodes of `scene`'s network.
    fn fastest(scene: &Scene) -> f64 {
        let p = scene.thermal.clone().expect("a thermal scene");
        let m = ThermalModel::new(scene, &p).expect("a valid network");
        let g = m.network.conductance_matrix();
        (0..NODES)
            .map(|k| g[k][k] / m.network.capacity_j_k[k] * m.macro_step_s)
            .fold(0.0, f64::max)
    }

    #[test]
    fn the_default_network_is_far_inside_the_rate_limit() {
        let mut scene = Scene::paper();
        scene.thermal = Some(ThermalParams::default());
        let r = fastest(&scene);
        eprintln!("default fastest rate x step: {r:e}");
        assert!(r > 0.0 && r < 1e-3 * MAX_RATE_TIMES_STEP, "{r:e}");
    }

    #[test]
    fn a_network_too_fast_to_step_is_refused_before_any_drop() {
        // Each within its field's range, each a network whose matrix exponential overflowed
        // (NaN temperatures) or never ended its squarings before the check.
        type Edit = fn(&mut ThermalParams);
        let cases: [(&str, Edit, &str); 3] = [
            (
                "lubricant",
                |p| p.lubricant_mass_kg = 1e-45,
                "outer_lubricant",
            ),
            ("housing", |p| p.housing_length_m = 1e-12, "housing"),
            (
                "outer race",
                |p| p.outer_race_mass_kg = 1e-300,
                "outer_race",
            ),
        ];
        for (what, edit, node) in cases {
            let mut p = ThermalParams::default();
            edit(&mut p);
            assert_eq!(p.validate(), Ok(()), "{what}: inside the field ranges");
            let mut scene = Scene::paper();
            scene.thermal = Some(p);
            let e = scene.validate().expect_err(what);
            assert_eq!(
                e.field,
                format!("thermal network, node {node}"),
                "{what}: {e}"
            );
            assert!(e.allowed.contains("rate times the step <= 1e6"), "{e}");
        }
        // Far past the default but a real bearing: a film of lubricant of a milligram.
        let mut scene = Scene::paper();
        scene.thermal = Some(ThermalParams {
            lubricant_mass_kg: 1e-6,
            ..Default::default()
        });
        assert_eq!(scene.validate(), Ok(()));
    }
}
