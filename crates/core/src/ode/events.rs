//! Locating a guard crossing on a step's interpolant.

/// Brackets the first crossing of `g` from `> 0` to `<= 0` in `[t0, t1]`.
///
/// `g(t0) = g0 > 0` and `g(t1) = g1 <= 0` are given. Returns `(lo, hi)` with `g(lo) > 0`,
/// `g(hi) <= 0` and `hi - lo` at the rounding level of `t` (the Illinois variant of regula
/// falsi, falling back to bisection when it stalls). The caller continues from `hi`, which is
/// strictly on the new side, so the next mode never starts with its own guard violated by
/// this crossing.
pub fn locate_crossing(
    mut g: impl FnMut(f64) -> f64,
    t0: f64,
    t1: f64,
    g0: f64,
    g1: f64,
) -> (f64, f64) {
    let (mut lo, mut hi) = (t0, t1);
    let (mut glo, mut ghi) = (g0, g1);
    let mut side = 0i8;
    let tol = 4.0 * f64::EPSILON * t1.abs().max(1e-12);
    for iter in 0..200 {
        if hi - lo <= tol {
            break;
        }
        // Illinois: secant, halving the stale end's weight when the same end is kept twice.
        let mut tm = if iter % 4 == 3 {
            0.5 * (lo + hi)
        } else {
            hi - ghi * (hi - lo) / (ghi - glo)
        };
        if !(tm > lo && tm < hi) {
            tm = 0.5 * (lo + hi);
        }
        let gm = g(tm);
        if gm > 0.0 {
            lo = tm;
            glo = gm;
            if side == 1 {
                ghi *= 0.5;
            }
            side = 1;
        } else {
            hi = tm;
            ghi = gm;
            if side == -1 {
                glo *= 0.5;
            }
            side = -1;
        }
    }
    (lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn brackets_a_simple_root_to_rounding() {
        let (lo, hi) = locate_crossing(|t| 1.0 - t * t, 0.0, 2.0, 1.0, -3.0);
        assert!(lo < 1.0 + 1e-15 && hi > 1.0 - 1e-15, "{lo} {hi}");
        assert!(hi - lo < 1e-14);
        assert!(1.0 - lo * lo > 0.0 && 1.0 - hi * hi <= 0.0);
    }

    #[test]
    fn handles_a_flat_then_steep_guard() {
        // A guard like a contact force: zero slope at one end, steep at the other.
        let f = |t: f64| 1e-9 - (t - 0.3).max(0.0).powf(10.0 / 9.0);
        let (lo, hi) = locate_crossing(f, 0.0, 1.0, f(0.0), f(1.0));
        assert!(f(lo) > 0.0 && f(hi) <= 0.0);
        assert!(hi - lo < 1e-14);
    }
}
