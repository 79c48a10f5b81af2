//! Hertz point contact of a ball in a raceway groove: the contact ellipse, the maximum
//! pressure and the load-deflection constant, solved exactly.
//!
//! Notation and relations follow Harris & Kotzalas, *Essential Concepts of Bearing
//! Technology*, 5th ed. (2006), ch. 2 (curvature sum `Σρ` and curvature difference `F(ρ)` of a
//! ball in a groove) and ch. 6 (the dimensionless semi-axes `a*`, `b*` and approach `δ*` of
//! the Hertz solution). The same coefficients are Hertz's `μ`, `ν` (Timoshenko & Goodier,
//! *Theory of Elasticity*, 3rd ed., § 140, the `m`, `n` table).
//!
//! ## The solution
//! With `κ = a/b` the ellipticity and `K`, `E` the complete elliptic integrals of the first
//! and second kind of parameter `m = 1 - 1/κ²` (modulus squared),
//!
//! ```text
//! F(ρ) = 1 - 2 (K/E - 1) / (κ² - 1)                      (solved for κ by Newton)
//! a* = (2 κ² E / π)^(1/3),  b* = (2 E / (π κ))^(1/3),  δ* = (2 K / π) (π / (2 κ² E))^(1/3)
//! L  = [ 3 Q / (2 Σρ) · ((1 - ν₁²)/E₁ + (1 - ν₂²)/E₂) ]^(1/3)
//! a = a* L,  b = b* L,  δ = δ* L² Σρ / 2,  p_max = 3 Q / (2 π a b)
//! ```
//!
//! `K` and `E` come from the arithmetic-geometric mean (Abramowitz & Stegun 17.6; DLMF
//! 19.8.1 and 19.8.6) to machine precision: no curve fits (the Hamrock-Brewe formulas are
//! only used as the Newton start).

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Complete elliptic integrals `(K(m), E(m))` of the first and second kind, parameter
/// `m = k²` in `[0, 1)`, by the arithmetic-geometric mean (DLMF 19.8.1 for `K`, 19.8.6 for
/// `E`; Abramowitz & Stegun 17.6). Converges quadratically: at most six iterations for the
/// ellipticities of bearing contacts.
///
/// # Panics
/// If `m` is not in `[0, 1)`.
pub fn complete_elliptic_integrals(m: f64) -> (f64, f64) {
    assert!(
        (0.0..1.0).contains(&m),
        "elliptic parameter m = {m} outside [0, 1)"
    );
    let mut a = 1.0_f64;
    let mut b = (1.0 - m).sqrt();
    let mut c = m.sqrt();
    // E = K (1 - sum_{n>=0} 2^(n-1) c_n^2), c_0 = k.
    let mut sum = 0.5 * c * c;
    let mut weight = 0.5;
    for _ in 0..64 {
        if c.abs() <= f64::EPSILON * a {
            break;
        }
        let a_next = 0.5 * (a + b);
        let b_next = (a * b).sqrt();
        c = 0.5 * (a - b);
        a = a_next;
        b = b_next;
        weight *= 2.0;
        sum += weight * c * c;
    }
    let k = PI / (2.0 * a);
    (k, k * (1.0 - sum))
}

/// The curvature difference `F(ρ)` that an ellipticity `κ = a/b >= 1` produces (Harris &
/// Kotzalas ch. 6): `F = 1 - 2 (K/E - 1) / (κ² - 1)`. Returns `(F, K, E)`.
pub fn curvature_difference_of_ellipticity(kappa: f64) -> (f64, f64, f64) {
    assert!(kappa >= 1.0, "ellipticity {kappa} < 1");
    if kappa == 1.0 {
        return (0.0, PI / 2.0, PI / 2.0);
    }
    let m = 1.0 - 1.0 / (kappa * kappa);
    let (k, e) = complete_elliptic_integrals(m);
    (1.0 - 2.0 * (k / e - 1.0) / (kappa * kappa - 1.0), k, e)
}

/// The ellipticity `κ = a/b` of the contact whose curvature difference is `f_rho` in
/// `[0, 1)`: the root of [`curvature_difference_of_ellipticity`], by Newton's method on
/// `ln κ` with the analytic derivatives of `K` and `E` (DLMF 19.4.1), safeguarded by
/// bisection, to a relative 1e-14. Started from Hamrock & Brewe's fit
/// `κ ≈ 1.0339 (R_y/R_x)^0.636`. `F(ρ) = 0` (equal principal curvatures) is the circle,
/// `κ = 1`.
pub fn ellipticity(f_rho: f64) -> f64 {
    assert!(
        (0.0..1.0).contains(&f_rho),
        "curvature difference {f_rho} outside [0, 1)"
    );
    if f_rho < 1e-12 {
        return 1.0;
    }
    // Bracket in x = ln(kappa): F rises monotonically from 0 (kappa = 1) to 1.
    let (mut lo, mut hi) = (0.0_f64, 25.0_f64);
    let radius_ratio = (1.0 + f_rho) / (1.0 - f_rho);
    let mut x = (1.0339 * radius_ratio.powf(0.636)).max(1.0 + 1e-6).ln();
    x = x.clamp(1e-9, hi);
    for _ in 0..100 {
        let kappa = x.exp();
        let (f, k, e) = curvature_difference_of_ellipticity(kappa);
        let g = f - f_rho;
        if g < 0.0 {
            lo = x;
        } else {
            hi = x;
        }
        // dF/dkappa: F = 1 - 2 h, h = (K/E - 1) / (kappa^2 - 1), m = 1 - 1/kappa^2.
        let m = 1.0 - 1.0 / (kappa * kappa);
        let dk_dm = (e - (1.0 - m) * k) / (2.0 * m * (1.0 - m));
        let de_dm = (e - k) / (2.0 * m);
        let dm_dkappa = 2.0 / (kappa * kappa * kappa);
        let q = kappa * kappa - 1.0;
        let d_ratio = (dk_dm * e - k * de_dm) / (e * e) * dm_dkappa;
        let dh = (d_ratio * q - (k / e - 1.0) * 2.0 * kappa) / (q * q);
        let dg_dx = -2.0 * dh * kappa;
        let mut next = if dg_dx > 0.0 && dg_dx.is_finite() {
            x - g / dg_dx
        } else {
            f64::NAN
        };
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        let done = (next - x).abs() <= 1e-14 * x.abs().max(1e-3);
        x = next;
        if done || hi - lo < 1e-15 {
            break;
        }
    }
    x.exp()
}

/// Which raceway a ball touches.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Race {
    /// The inner raceway: convex along the rolling direction.
    Inner,
    /// The outer raceway: concave along the rolling direction.
    Outer,
}

/// Curvature sum `Σρ` (1/m) and curvature difference `F(ρ)` of a ball in a groove (Harris &
/// Kotzalas ch. 2). With `γ = D cos α / d_m`:
///
/// ```text
/// ball:        ρ_I1 = ρ_I2 = 2/D
/// inner race:  ρ_II1 =  (2/D) γ/(1 - γ),   ρ_II2 = -1/(f_i D)
/// outer race:  ρ_II1 = -(2/D) γ/(1 + γ),   ρ_II2 = -1/(f_o D)
/// Σρ = ρ_I1 + ρ_I2 + ρ_II1 + ρ_II2,   F(ρ) = ((ρ_I1 - ρ_I2) + (ρ_II1 - ρ_II2)) / Σρ
/// ```
///
/// `conformity` is the groove radius over the ball diameter, `f = r/D` (> 0.5).
pub fn ball_in_groove_curvature(
    race: Race,
    ball_diameter_m: f64,
    pitch_diameter_m: f64,
    contact_angle_rad: f64,
    conformity: f64,
) -> (f64, f64) {
    let d = ball_diameter_m;
    let gamma = d * contact_angle_rad.cos() / pitch_diameter_m;
    let rho_ball = 2.0 / d;
    let rho_ii1 = match race {
        Race::Inner => rho_ball * gamma / (1.0 - gamma),
        Race::Outer => -rho_ball * gamma / (1.0 + gamma),
    };
    let rho_ii2 = -1.0 / (conformity * d);
    let sum = 2.0 * rho_ball + rho_ii1 + rho_ii2;
    let diff = (rho_ii1 - rho_ii2) / sum;
    (sum, diff)
}

/// The contact ellipse under one load (Harris & Kotzalas ch. 6).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ContactEllipse {
    /// Semi-major axis `a` (m), across the rolling direction for a ball in a groove.
    pub semi_major_m: f64,
    /// Semi-minor axis `b` (m), along the rolling direction.
    pub semi_minor_m: f64,
    /// Maximum (central) contact pressure `p_max = 3 Q / (2 π a b)` (Pa).
    pub max_pressure_pa: f64,
    /// Elastic approach of the two bodies `δ` (m).
    pub approach_m: f64,
}

impl ContactEllipse {
    /// The unloaded contact: a point.
    pub const ZERO: ContactEllipse = ContactEllipse {
        semi_major_m: 0.0,
        semi_minor_m: 0.0,
        max_pressure_pa: 0.0,
        approach_m: 0.0,
    };
}

/// One Hertz point contact with its geometry and materials solved once: the ellipse, the
/// pressure and the stiffness then follow from the load by powers (Harris & Kotzalas ch. 6).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PointContact {
    /// Curvature sum `Σρ` (1/m).
    pub curvature_sum_per_m: f64,
    /// Curvature difference `F(ρ)` (-).
    pub curvature_difference: f64,
    /// Ellipticity `κ = a/b` (-).
    pub ellipticity: f64,
    /// Complete elliptic integral of the first kind `K` at `m = 1 - 1/κ²`.
    pub elliptic_k: f64,
    /// Complete elliptic integral of the second kind `E` at `m = 1 - 1/κ²`.
    pub elliptic_e: f64,
    /// Dimensionless semi-major axis `a*` (Hertz's `μ`).
    pub a_star: f64,
    /// Dimensionless semi-minor axis `b*` (Hertz's `ν`).
    pub b_star: f64,
    /// Dimensionless approach `δ*`.
    pub delta_star: f64,
    /// Elastic compliance sum `(1 - ν₁²)/E₁ + (1 - ν₂²)/E₂` (1/Pa).
    pub compliance_per_pa: f64,
}

impl PointContact {
    /// A contact of curvature sum `curvature_sum_per_m` (1/m) and curvature difference
    /// `curvature_difference` in `[0, 1)` between materials of compliance sum
    /// `compliance_per_pa` = `(1 - ν₁²)/E₁ + (1 - ν₂²)/E₂` (1/Pa).
    pub fn new(
        curvature_sum_per_m: f64,
        curvature_difference: f64,
        compliance_per_pa: f64,
    ) -> Self {
        let kappa = ellipticity(curvature_difference);
        let (_, k, e) = curvature_difference_of_ellipticity(kappa);
        PointContact {
            curvature_sum_per_m,
            curvature_difference,
            ellipticity: kappa,
            elliptic_k: k,
            elliptic_e: e,
            a_star: (2.0 * kappa * kappa * e / PI).cbrt(),
            b_star: (2.0 * e / (PI * kappa)).cbrt(),
            delta_star: 2.0 * k / PI * (PI / (2.0 * kappa * kappa * e)).cbrt(),
            compliance_per_pa,
        }
    }

    /// A ball of one steel in a groove of the same steel ([`ball_in_groove_curvature`]):
    /// Young's modulus `young_modulus_pa`, Poisson's ratio `poisson_ratio` for both bodies.
    pub fn ball_in_groove(
        race: Race,
        ball_diameter_m: f64,
        pitch_diameter_m: f64,
        contact_angle_rad: f64,
        conformity: f64,
        young_modulus_pa: f64,
        poisson_ratio: f64,
    ) -> Self {
        let (sum, diff) = ball_in_groove_curvature(
            race,
            ball_diameter_m,
            pitch_diameter_m,
            contact_angle_rad,
            conformity,
        );
        let compliance = 2.0 * (1.0 - poisson_ratio * poisson_ratio) / young_modulus_pa;
        PointContact::new(sum, diff, compliance)
    }

    /// The length scale `L = [3 Q / (2 Σρ) · compliance]^(1/3)` (m) of load `q_n` (N).
    fn length_scale_m(&self, q_n: f64) -> f64 {
        (1.5 * q_n / self.curvature_sum_per_m * self.compliance_per_pa).cbrt()
    }

    /// The contact ellipse under the normal load `q_n` (N); zero for `q_n <= 0`.
    pub fn ellipse(&self, q_n: f64) -> ContactEllipse {
        if !(q_n > 0.0) {
            return ContactEllipse::ZERO;
        }
        let l = self.length_scale_m(q_n);
        let a = self.a_star * l;
        let b = self.b_star * l;
        ContactEllipse {
            semi_major_m: a,
            semi_minor_m: b,
            max_pressure_pa: 3.0 * q_n / (2.0 * PI * a * b),
            approach_m: self.delta_star * l * l * self.curvature_sum_per_m / 2.0,
        }
    }

    /// Maximum contact pressure (Pa) under the normal load `q_n` (N): grows as `Q^(1/3)`.
    pub fn max_pressure_pa(&self, q_n: f64) -> f64 {
        self.ellipse(q_n).max_pressure_pa
    }

    /// The normal load (N) at which the maximum pressure reaches `pressure_pa`: the inverse
    /// of [`Self::max_pressure_pa`], `Q = p³ (2π a* b*)³ / 9 · (3 compliance/(2 Σρ))²`.
    pub fn load_at_pressure_n(&self, pressure_pa: f64) -> f64 {
        // p = 3 Q / (2 pi a* b* L^2), L^3 = c Q with c = 3 compliance / (2 sum)
        // => p = 3 Q^(1/3) / (2 pi a* b* c^(2/3)) => Q = (2 pi a* b* c^(2/3) p / 3)^3.
        let c = 1.5 * self.compliance_per_pa / self.curvature_sum_per_m;
        (2.0 * PI * self.a_star * self.b_star * c.powf(2.0 / 3.0) * pressure_pa / 3.0).powi(3)
    }

    /// The load-deflection constant `K` of `Q = K δ^1.5` (N/m^1.5): from
    /// `δ = δ* L² Σρ / 2` with `L³ ∝ Q`.
    pub fn stiffness_n_per_m1_5(&self) -> f64 {
        let c = 1.5 * self.compliance_per_pa / self.curvature_sum_per_m;
        // delta = delta* c^(2/3) Q^(2/3) sum / 2  =>  Q = (delta / (delta* c^(2/3) sum / 2))^1.5
        (self.delta_star * c.powf(2.0 / 3.0) * self.curvature_sum_per_m / 2.0).powf(-1.5)
    }
}

/// The load-deflection constant of a ball squeezed between two raceways, contacts in series
/// (Harris & Kotzalas ch. 7): the approaches add at equal load, so
/// `K_n = (K_i^(-2/3) + K_o^(-2/3))^(-3/2)`.
pub fn series_stiffness_n_per_m1_5(k_inner: f64, k_outer: f64) -> f64 {
    (k_inner.powf(-2.0 / 3.0) + k_outer.powf(-2.0 / 3.0)).powf(-1.5)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elliptic_integrals_at_known_points() {
        // m = 0: K = E = pi/2. m = 1/2: Abramowitz & Stegun Table 17.1 / DLMF 19.6.
        let (k, e) = complete_elliptic_integrals(0.0);
        assert_eq!((k, e), (PI / 2.0, PI / 2.0));
        let (k, e) = complete_elliptic_integrals(0.5);
        assert!((k - 1.854_074_677_301_372).abs() < 1e-14, "K(1/2) = {k}");
        assert!((e - 1.350_643_881_047_675_5).abs() < 1e-14, "E(1/2) = {e}");
        // Legendre's relation at m = 1/2: 2 E K - K^2 = pi/2.
        assert!((2.0 * e * k - k * k - PI / 2.0).abs() < 1e-14);
    }

    #[test]
    fn legendre_relation_holds_across_the_range() {
        // E(m) K(1-m) + E(1-m) K(m) - K(m) K(1-m) = pi/2 (DLMF 19.7.1).
        for m in [1e-6, 0.01, 0.1, 0.3, 0.7, 0.9, 0.99, 0.999_9] {
            let (k, e) = complete_elliptic_integrals(m);
            let (kc, ec) = complete_elliptic_integrals(1.0 - m);
            let r = e * kc + ec * k - k * kc - PI / 2.0;
            assert!(r.abs() < 1e-13, "m {m}: {r:e}");
        }
    }

    #[test]
    fn ellipticity_inverts_the_curvature_difference() {
        for kappa in [1.001, 1.3, 2.0, 5.0, 8.7, 20.0, 100.0] {
            let (f, _, _) = curvature_difference_of_ellipticity(kappa);
            let back = ellipticity(f);
            assert!((back / kappa - 1.0).abs() < 1e-10, "kappa {kappa}: {back}");
        }
        assert_eq!(ellipticity(0.0), 1.0);
    }

    #[test]
    fn sphere_on_sphere_is_the_circular_hertz_solution() {
        // Two equal steel balls of radius R: curvature sum 4/R, F = 0, a = b =
        // (3 Q R* / (4 E*))^(1/3) with R* = R/2, 1/E* = compliance (Johnson, Contact
        // Mechanics, eq. 4.22); p0 = 3 Q / (2 pi a^2); delta = a^2 / R*.
        let r = 0.004;
        let compliance = 2.0 * (1.0 - 0.09) / 208e9;
        let c = PointContact::new(4.0 / r, 0.0, compliance);
        let q = 500.0;
        let el = c.ellipse(q);
        let r_star = r / 2.0;
        let a = (3.0 * q * r_star * compliance / 4.0).cbrt();
        assert!((el.semi_major_m / a - 1.0).abs() < 1e-13);
        assert!((el.semi_minor_m / a - 1.0).abs() < 1e-13);
        assert!((el.max_pressure_pa / (3.0 * q / (2.0 * PI * a * a)) - 1.0).abs() < 1e-13);
        assert!((el.approach_m / (a * a / r_star) - 1.0).abs() < 1e-13);
    }

    #[test]
    fn stiffness_and_pressure_inverse_are_consistent() {
        let c = PointContact::ball_in_groove(
            Race::Inner,
            5.5e-3,
            0.051,
            15f64.to_radians(),
            0.52,
            208e9,
            0.3,
        );
        for q in [1.0, 100.0, 2500.0] {
            let el = c.ellipse(q);
            let k = c.stiffness_n_per_m1_5();
            assert!((k * el.approach_m.powf(1.5) / q - 1.0).abs() < 1e-12);
            assert!((c.load_at_pressure_n(el.max_pressure_pa) / q - 1.0).abs() < 1e-12);
        }
    }
}
