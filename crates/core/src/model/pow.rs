//! `x^p` for the model's fractional powers: the Hertz law's `delta^e` of eq. 7 (e = 10/9 at
//! the rotor-race contact) and Palmgren's `(nu0 n)^(2/3)` and `(P/C0)^0.33` of eqs. 12-13.
//!
//! Written here rather than taken from libm because these three powers were 58 % of one
//! right-hand-side evaluation with glibc's `pow` (36 of 62 ns). This one is a log and an exp
//! on two 256-entry tables, inlined, with no special-case handling on the fast path and no
//! extended-precision arithmetic (the price: an error of a few times `|p ln x|` ulp instead
//! of glibc's half an ulp, about 1e-14 for the model's usual arguments). Three powers side by
//! side cost 0.67 of glibc's time, and one RHS evaluation fell from 63.5-64 ns to 46.5-47.8 ns
//! (docs/performance.md). The `libm` crate, a pure-Rust port of musl, took 3.1 times glibc's
//! time.

use super::pow_tables::{EXP_TABLE, LOG_TABLE};

/// `ln 2` in two parts; `k * LN2_HI` is exact for every exponent `k` of a double.
const LN2_HI: f64 = f64::from_bits(0x3fe62e42fefa3800);
const LN2_LO: f64 = f64::from_bits(0x3d2ef35793c76730);
/// The bits of 0.6875: `x = 2^k z` with `z` in `[0.6875, 1.375)`.
const OFF: u64 = 0x3fe6000000000000;
/// `256 / ln 2`.
const INV_LN2_N: f64 = f64::from_bits(0x40771547652b82fe);
/// `1.5 * 2^52`: adding it rounds to an integer held in the low bits.
const SHIFT: f64 = f64::from_bits(0x4338000000000000);
/// `-ln 2 / 256` in two parts; the first has 34 significant bits, so its product with any
/// `m` below `2^18` (every `|p ln x| <= 700`) is exact.
const NEG_LN2_HI_N: f64 = f64::from_bits(0xbf662e42fef80000);
const NEG_LN2_LO_N: f64 = f64::from_bits(0xbd31cf79abc9e3b4);
/// Beyond `|p ln x|` of this the result nears the ends of the doubles' range (e^700 is about
/// 1e304), where the exponent arithmetic below would not hold, and libm takes it.
const Y_MAX: f64 = 700.0;

/// `x^p` for `x >= 0`, within `2^-53 (3 |p ln x| + 2 |p| + 4)` of the exact power, relative:
/// below 1.1e-14 for penetrations from 1e-12 m to 1 mm and every argument of the drag (at
/// most 6e-15 measured there), below 1.8e-14 down to a penetration of 1e-20 m. `x = 1` gives
/// 1 only to within that bound (`ln 1` comes out near 1e-17).
///
/// `x = 2^k z`, `ln z = ln c + ln(1 + r)` with `c` one of 256 table points and
/// `|r| < 0.002` (a degree-5 series); then `exp(p ln x) = 2^(m/256) e^s` with `|s| < 0.0014`
/// (a degree-4 series) and `2^(j/256)` from the second table. Only additions,
/// multiplications and bit operations, so the bits do not depend on the machine or on libm.
/// Zero, subnormal, infinite, negative and NaN inputs, a NaN `p`, and `|p ln x| > 700`, are
/// passed to [`f64::powf`].
#[inline]
pub fn pow(x: f64, p: f64) -> f64 {
    let ix = x.to_bits();
    // Positive normal finite x only: a negative x's sign bit makes its bits too large.
    const MIN_NORMAL: u64 = 0x0010_0000_0000_0000;
    const INF: u64 = 0x7ff0_0000_0000_0000;
    if ix.wrapping_sub(MIN_NORMAL) >= INF - MIN_NORMAL {
        return libm_pow(x, p);
    }
    let tmp = ix.wrapping_sub(OFF);
    let i = ((tmp >> 44) % 256) as usize;
    let k = (tmp as i64 >> 52) as f64;
    let z = f64::from_bits(ix.wrapping_sub(tmp & (0xfff << 52)));
    let (invc, logc) = LOG_TABLE[i];
    let (invc, logc) = (f64::from_bits(invc), f64::from_bits(logc));
    let r = z * invc - 1.0;
    let r2 = r * r;
    // ln(1 + r) - r, Taylor to r^5 (the r^6 term is below 1e-17).
    let tail = r2 * (-0.5 + r * (1.0 / 3.0)) + r2 * r2 * (-0.25 + r * 0.2);
    let hi = k * LN2_HI + logc;
    let ln_x = hi + (k * LN2_LO + r + tail);
    let y = p * ln_x;
    if !(y.abs() <= Y_MAX) {
        return libm_pow(x, p);
    }
    // exp(y) = 2^(m/256) e^s, m = round(y 256 / ln 2): the table gives 2^(j/256), j = m mod
    // 256, and m / 256 rounded down goes into the exponent bits.
    let kd = y * INV_LN2_N + SHIFT;
    let ki = kd.to_bits();
    let kd = kd - SHIFT;
    let s = y + kd * NEG_LN2_HI_N + kd * NEG_LN2_LO_N;
    let scale = f64::from_bits(EXP_TABLE[(ki % 256) as usize].wrapping_add(ki << 44));
    let s2 = s * s;
    // e^s - 1, Taylor to s^4 (the s^5 term is below 4e-17).
    let em1 = s + s2 * (0.5 + s * (1.0 / 6.0)) + s2 * s2 * (1.0 / 24.0);
    scale + scale * em1
}

/// The inputs [`pow`] leaves to libm, kept out of its inlined body.
#[cold]
#[inline(never)]
fn libm_pow(x: f64, p: f64) -> f64 {
    x.powf(p)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bound of [`pow`]'s doc comment, at `x^p`: the rounding of `ln x` in two sums and of
    /// `p ln x` (three times `|p ln x|` half-ulps), the table's `ln c` and the series' `r`
    /// (`2 |p|`), and the exp's table, series and last sum with libm's own half ulp (4).
    fn bound(x: f64, p: f64) -> f64 {
        f64::EPSILON / 2.0 * (3.0 * (p * x.ln()).abs() + 2.0 * p.abs() + 4.0)
    }

    /// The largest error over `x` log-spaced from 1e-300 to 1e300, at and next to each
    /// edge of the log table's intervals, and at the powers where the exp table's index turns
    /// over, as a fraction of [`bound`].
    fn worst_over_bound(p: f64) -> f64 {
        let mut xs = Vec::new();
        let mut x: f64 = 1e-300;
        while x < 1e300 {
            xs.push(x);
            x *= 1.000_37;
        }
        for e in [-40, -20, -1, 0, 1, 17, 40] {
            for i in 0..=256u64 {
                let edge = f64::from_bits(OFF + (i << 44)) * 2f64.powi(e);
                xs.extend([
                    edge,
                    f64::from_bits(edge.to_bits() - 1),
                    f64::from_bits(edge.to_bits() + 1),
                ]);
            }
        }
        for m in -2000..2000 {
            // p ln x = (m + 1/2) ln 2 / 256: the exp's rounding of m turns over.
            xs.push(((m as f64 + 0.5) * std::f64::consts::LN_2 / 256.0 / p).exp());
        }
        let mut worst: f64 = 0.0;
        for x in xs {
            if (p * x.ln()).abs() > Y_MAX {
                assert_eq!(pow(x, p).to_bits(), x.powf(p).to_bits(), "x {x:e}, p {p}");
                continue;
            }
            let exact = x.powf(p);
            worst = worst.max((pow(x, p) - exact).abs() / exact / bound(x, p));
        }
        worst
    }

    #[test]
    fn within_its_bound_of_libm() {
        for p in [10.0 / 9.0, 2.0 / 3.0, 0.33, 1.5, 1.0, 2.7, 0.1, 7.5, -0.25] {
            let w = worst_over_bound(p);
            assert!(w <= 1.0, "p {p}: {w} of the bound");
        }
    }

    #[test]
    fn model_powers_within_1e_14() {
        // The model's powers over the ranges they meet: a penetration from 1e-12 m to 1 mm,
        // nu0 n up to 1e7 (mm^2/s r/min), a load ratio from 1e-9 to 10. The bound allows
        // 1.1e-14 there; 1e-14 is a measured margin (the worst is 6e-15).
        for (p, lo, hi) in [
            (10.0 / 9.0, 1e-12, 1e-3),
            (2.0 / 3.0, 1.0, 1e7),
            (0.33, 1e-9, 10.0),
        ] {
            let mut x: f64 = lo;
            while x < hi {
                let rel = (pow(x, p) - x.powf(p)).abs() / x.powf(p);
                assert!(rel < 1e-14, "x {x:e}, p {p}: {rel:e}");
                x *= 1.000_1;
            }
        }
    }

    #[test]
    fn special_inputs_are_libms() {
        let tiny = f64::from_bits(1);
        for x in [
            0.0,
            -0.0,
            tiny,
            f64::MIN_POSITIVE / 3.0,
            -2.0,
            f64::INFINITY,
            f64::NAN,
        ] {
            for p in [10.0 / 9.0, 0.33] {
                assert_eq!(pow(x, p).to_bits(), x.powf(p).to_bits(), "x {x:e}, p {p}");
            }
        }
        assert_eq!(pow(0.0, 2.0 / 3.0), 0.0);
        // The smallest normal double takes the table path.
        let m = f64::MIN_POSITIVE;
        assert!((pow(m, 0.33) - m.powf(0.33)).abs() <= bound(m, 0.33) * m.powf(0.33));
    }

    #[test]
    fn tables_hold_their_values_to_an_ulp() {
        // Correct rounding is the generator's (50 digits; `scripts/test.sh` checks that it
        // still writes this file): libm's ln and exp2 here are good to about an ulp.
        for (i, &(invc, logc)) in LOG_TABLE.iter().enumerate() {
            let (invc, logc) = (f64::from_bits(invc), f64::from_bits(logc));
            let lo = f64::from_bits(OFF + ((i as u64) << 44));
            let hi = f64::from_bits(OFF + ((i as u64 + 1) << 44));
            let c = 0.5 * (lo + hi);
            assert!((invc * c - 1.0).abs() <= f64::EPSILON, "entry {i}");
            // -ln(invc) to the nearest double; libm's ln is within an ulp of it.
            let ulp = f64::EPSILON * logc.abs().max(f64::MIN_POSITIVE);
            assert!((logc + invc.ln()).abs() <= ulp, "entry {i}");
        }
        for (j, &t) in EXP_TABLE.iter().enumerate() {
            let v = f64::from_bits(t + ((j as u64) << 44));
            let exact = (j as f64 / 256.0).exp2();
            assert!((v - exact).abs() <= f64::EPSILON * exact, "entry {j}");
        }
    }
}
