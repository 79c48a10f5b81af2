//! The damped Hertz contact law, eq. 7: `F_n = K delta^e + C delta_dot` for `delta > 0`,
//! and a damper that never pulls (the contact separates when that sum reaches zero).

/// `sign(x) |x|^e`: the elastic term of eq. 7, continued oddly to `x < 0` so a mode's
/// right-hand side stays smooth when a Runge-Kutta stage overshoots the contact edge.
#[inline]
pub fn signed_pow(x: f64, e: f64) -> f64 {
    let a = x.abs();
    let p = if e == 1.5 {
        a * a.sqrt()
    } else {
        // The model's own power (model/pow.rs): faster here than glibc's pow, and far faster
        // than two `cbrt` calls (a slow software cube root: 34 % of a drop's time once).
        super::pow::pow(a, e)
    };
    if x < 0.0 {
        -p
    } else {
        p
    }
}

/// Force of eq. 7 before the never-pull switch (N): `K sign(d)|d|^e + C d_dot`.
/// Its sign, together with `delta`, decides whether the contact is active.
#[inline]
pub fn raw_force(k: f64, e: f64, c: f64, delta: f64, delta_dot: f64) -> f64 {
    k * signed_pow(delta, e) + c * delta_dot
}

/// Elastic energy stored at penetration `delta` (J): `K |delta|^(e+1) / (e+1)`.
#[inline]
pub fn elastic_energy(k: f64, e: f64, delta: f64) -> f64 {
    k * delta.abs() * signed_pow(delta, e).abs() / (e + 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn signed_pow_matches_powf() {
        for x in [1e-9, 3.7e-7, 2e-6, 0.5, 1.0, 3.0] {
            for e in [1.5, 10.0 / 9.0] {
                let rel = (signed_pow(x, e) - x.powf(e)).abs() / x.powf(e);
                assert!(rel < 1e-14, "x {x} e {e} rel {rel:e}");
                assert_eq!(signed_pow(-x, e), -signed_pow(x, e));
            }
        }
    }

    #[test]
    fn elastic_energy_is_the_integral_of_the_force() {
        let (k, e, d) = (1.988e9, 10.0 / 9.0, 2e-6);
        let n = 20_000;
        let mut w = 0.0;
        for i in 0..n {
            let x = (i as f64 + 0.5) * d / n as f64;
            w += raw_force(k, e, 0.0, x, 0.0) * d / n as f64;
        }
        assert!((w - elastic_energy(k, e, d)).abs() / w < 1e-6);
    }
}
