//! Reduced model: the race's translation treated as massless (quasi-static race).
//!
//! The full model gives the light race (48 g) its own translational dynamics between two
//! stiff Hertz contacts, eq. 7 for the rotor-race contact (`k1`, `e1 = 10/9`) and the ball
//! support (`k2`, `e2 = 3/2`). That mode rings at about 16 kHz and sets the stability limit
//! of an explicit integrator. With the race's translational inertia (and weight) neglected,
//! the race centre follows from the force balance instead: both springs carry the same
//! force `F`, so they act in series along the line from the housing centre to the rotor
//! centre, and the combined penetration `D = |O_r| - s` splits as `D = delta + r` with
//!
//! `k1 delta^e1 = k2 r^e2 = F`.
//!
//! Damping: for the rates we use the elastic split, `delta' = w1 D'` and `r' = w2 D'` with
//! `w_i` the compliance shares (`w1 = (delta/e1) / (delta/e1 + r/e2)`, `w2 = 1 - w1`), and the
//! rotor feels `c_eff D'` with `c_eff = c1 w1^2 + c2 w2^2`, so the damping power
//! `c_eff D'^2 = c1 delta'^2 + c2 r'^2` is exactly what the two dampers would dissipate at
//! those rates (the energy audit stays exact). Two Kelvin-Voigt elements in series are not
//! a Kelvin-Voigt element, so this is an approximation; so is ignoring the small tangential
//! offset of the race that the friction force would cause. The race keeps its rotation
//! (inertia `J_b`, friction torque, Palmgren drag with `P1 = F`).
//!
//! What it costs in accuracy is measured, not assumed (`whirlmap accuracy`, docs/accuracy.md).

/// The series split of a combined penetration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Split {
    /// The common elastic force `F` (N), signed like the penetration (odd continuation).
    pub force_n: f64,
    /// Rotor-race penetration delta (m), >= 0.
    pub delta_m: f64,
    /// Race displacement on its support r (m), >= 0.
    pub support_m: f64,
    /// Share of a combined rate taken by the rotor-race contact, `w1` in [0, 1].
    pub w_contact: f64,
}

/// `ln |D|` range of the start table (m): 1e-13 m to 1e-2 m covers every penetration a
/// valid scene reaches; outside it the split starts from the softer spring alone.
const TABLE_Z0: f64 = -30.0;
/// Table spacing in `ln |D|`. `ln F` is a very smooth function of `ln D` (its slope moves
/// from `e2` to `e1` over a few units), so cubic Hermite interpolation on this grid is good
/// to about 1e-8, and one Newton step takes that to rounding.
const TABLE_H: f64 = 0.25;
const TABLE_LEN: usize = 104;

/// Two Hertz springs in series, prepared once.
#[derive(Debug, Clone, PartialEq)]
pub struct SeriesSprings {
    /// `ln k1`.
    ln_k1: f64,
    /// `1/e1`.
    p: f64,
    /// `ln k2`.
    ln_k2: f64,
    /// `1/e2`.
    q: f64,
    e1: f64,
    e2: f64,
    /// `(ln F, d ln F / d ln D)` at `ln D = TABLE_Z0 + i TABLE_H`: Newton's start.
    table: Vec<(f64, f64)>,
}

impl SeriesSprings {
    /// Springs `k1 delta^e1` and `k2 r^e2` (N/m^e, exponents in [1, 2]).
    pub fn new(k1: f64, e1: f64, k2: f64, e2: f64) -> Self {
        let mut s = Self {
            ln_k1: k1.ln(),
            p: 1.0 / e1,
            ln_k2: k2.ln(),
            q: 1.0 / e2,
            e1,
            e2,
            table: Vec::new(),
        };
        s.table = (0..TABLE_LEN)
            .map(|i| {
                let z = TABLE_Z0 + i as f64 * TABLE_H;
                let x = s.solve_ln_force(z, s.cold_start(z));
                let (a, b) = s.penetrations(x);
                (x, (a + b) / (s.p * a + s.q * b))
            })
            .collect();
        s
    }

    /// `ln F` of the softer spring alone at `ln D = z`: an upper bound of the series force.
    fn cold_start(&self, z: f64) -> f64 {
        (self.ln_k1 + self.e1 * z).min(self.ln_k2 + self.e2 * z)
    }

    /// `(delta, r)` at `ln F = x`.
    #[inline]
    fn penetrations(&self, x: f64) -> (f64, f64) {
        (
            (self.p * (x - self.ln_k1)).exp(),
            (self.q * (x - self.ln_k2)).exp(),
        )
    }

    /// Newton's method for `ln F` at `ln D = z` from `x`, to rounding.
    fn solve_ln_force(&self, z: f64, mut x: f64) -> f64 {
        let d = z.exp();
        for _ in 0..60 {
            let (a, b) = self.penetrations(x);
            let dx = (a + b - d) / (self.p * a + self.q * b);
            x -= dx;
            if dx.abs() < 1e-15 * x.abs().max(1.0) {
                break;
            }
        }
        x
    }

    /// Newton's start at `ln D = z`: cubic Hermite on the table, or the cold start outside.
    #[inline]
    fn warm_start(&self, z: f64) -> Option<f64> {
        let u = (z - TABLE_Z0) / TABLE_H;
        if !(u >= 0.0 && u < (TABLE_LEN - 1) as f64) {
            return None;
        }
        let i = u as usize;
        let t = u - i as f64;
        let ((x0, s0), (x1, s1)) = (self.table[i], self.table[i + 1]);
        let (t2, t3) = (t * t, t * t * t);
        Some(
            (2.0 * t3 - 3.0 * t2 + 1.0) * x0
                + (t3 - 2.0 * t2 + t) * TABLE_H * s0
                + (-2.0 * t3 + 3.0 * t2) * x1
                + (t3 - t2) * TABLE_H * s1,
        )
    }

    /// Splits the combined penetration `d_m`: solves `(F/k1)^(1/e1) + (F/k2)^(1/e2) = |d|`
    /// for `F` by Newton's method in `x = ln F`. The left side is a sum of exponentials of
    /// `x`, convex and increasing. Inside the table's range one Newton step from the
    /// interpolated start reaches rounding (4 transcendental calls in all); outside it the
    /// iteration starts from the softer spring alone, right of the root, and converges
    /// monotonically. Odd in `d_m`, so a stage that overshoots the contact edge stays smooth.
    pub fn split(&self, d_m: f64) -> Split {
        let d = d_m.abs();
        if d == 0.0 || !d.is_finite() {
            return Split {
                force_n: 0.0,
                delta_m: 0.0,
                support_m: 0.0,
                w_contact: 0.0,
            };
        }
        let z = d.ln();
        let (x, a, b) = match self.warm_start(z) {
            Some(x0) => {
                let (a, b) = self.penetrations(x0);
                let dx = (a + b - d) / (self.p * a + self.q * b);
                // The step is about 1e-8: first-order updates of a and b are exact to
                // rounding.
                (x0 - dx, a * (1.0 - self.p * dx), b * (1.0 - self.q * dx))
            }
            None => {
                let x = self.solve_ln_force(z, self.cold_start(z));
                let (a, b) = self.penetrations(x);
                (x, a, b)
            }
        };
        let (c1, c2) = (a * self.p, b * self.q);
        Split {
            force_n: x.exp().copysign(d_m),
            delta_m: a,
            support_m: b,
            w_contact: c1 / (c1 + c2),
        }
    }

    /// `1/e1`: with `1/e2`, the split's stiffness is `dF/dd = F / (delta/e1 + r/e2)`.
    pub fn inv_e1(&self) -> f64 {
        self.p
    }

    /// `1/e2`.
    pub fn inv_e2(&self) -> f64 {
        self.q
    }

    /// Elastic energy held by both springs at a split (J): `F delta/(e1+1) + F r/(e2+1)`.
    pub fn energy_j(&self, s: &Split) -> f64 {
        s.force_n.abs() * (s.delta_m / (self.e1 + 1.0) + s.support_m / (self.e2 + 1.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn paper() -> SeriesSprings {
        SeriesSprings::new(1.988e9, 10.0 / 9.0, 7.811e9, 1.5)
    }

    #[test]
    fn both_springs_carry_the_same_force_and_the_penetrations_add_up() {
        let s = paper();
        // Inside the table, at its edges and outside it (1e-14 m, 0.05 m).
        for d in [1e-14, 1e-12, 1e-9, 3.7e-7, 4e-6, 2e-5, 1e-3, 0.05] {
            let sp = s.split(d);
            let f1 = 1.988e9 * sp.delta_m.powf(10.0 / 9.0);
            let f2 = 7.811e9 * sp.support_m.powf(1.5);
            assert!(
                (f1 - sp.force_n).abs() < 1e-12 * sp.force_n,
                "d {d}: {f1} {}",
                sp.force_n
            );
            assert!(
                (f2 - sp.force_n).abs() < 1e-12 * sp.force_n,
                "d {d}: {f2} {}",
                sp.force_n
            );
            assert!((sp.delta_m + sp.support_m - d).abs() < 1e-14 * d, "d {d}");
            assert!((0.0..=1.0).contains(&sp.w_contact));
            assert_eq!(s.split(-d).force_n, -sp.force_n);
        }
    }

    #[test]
    fn elastic_energy_is_the_integral_of_the_force() {
        let s = paper();
        let d = 5e-6;
        let n = 20_000;
        let mut w = 0.0;
        for i in 0..n {
            let x = (i as f64 + 0.5) * d / n as f64;
            w += s.split(x).force_n * d / n as f64;
        }
        let e = s.energy_j(&s.split(d));
        assert!((w - e).abs() / e < 1e-6, "{w} vs {e}");
    }

    #[test]
    fn compliance_share_is_the_derivative_of_the_contact_penetration() {
        let s = paper();
        let d = 3e-6;
        let h = 1e-12;
        let fd = (s.split(d + h).delta_m - s.split(d - h).delta_m) / (2.0 * h);
        assert!(
            (fd - s.split(d).w_contact).abs() < 1e-5,
            "{fd} {}",
            s.split(d).w_contact
        );
    }
}
