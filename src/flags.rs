//! clap value parsers for the number flags. Text that is not a number of the right kind is
//! refused with the flag's allowed range (clap prefixes the flag and the text), taken from the
//! check the value meets once it is a number, so each range is written in one place.

use whirlmap_core::scene::num;
use whirlmap_core::InvalidParameter;
use whirlmap_core::{DropOptions, Scene};
use whirlmap_sweep::compare::Thresholds;
use whirlmap_sweep::critical::{check_mus, CriticalOptions};
use whirlmap_sweep::shard::MAX_SHARDS;

/// A clap value parser: a finite or infinite number (`1e3`, `-0.5`; `-0` reads as 0, so it
/// is echoed and hashed as 0), else "not a number; allowed `<range>`" with the range `allowed`
/// states.
pub(crate) fn number(
    allowed: fn() -> String,
) -> impl Fn(&str) -> Result<f64, String> + Clone + Send + Sync + 'static {
    move |text: &str| {
        text.trim()
            .parse::<f64>()
            // -0 + 0 is +0 (round to nearest); every other number is unchanged.
            .map(|x| x + 0.0)
            .map_err(|_| format!("not a number; allowed {}", allowed()))
    }
}

/// A clap value parser: a whole number in `[lo, hi]`, else the reason and that range.
pub(crate) fn whole<T: TryFrom<u64> + Clone + Send + Sync + 'static>(
    lo: u64,
    hi: u64,
) -> impl Fn(&str) -> Result<T, String> + Clone + Send + Sync + 'static {
    move |text: &str| {
        let range = format!("[{lo}, {hi}]");
        // Read wide, so a negative or huge whole number is out of range, not "not whole".
        match text.trim().parse::<i128>() {
            Ok(n) if (i128::from(lo)..=i128::from(hi)).contains(&n) => {
                T::try_from(n as u64).map_err(|_| format!("{n} is too large; allowed {range}"))
            }
            Ok(n) => Err(format!("{n} is out of range; allowed {range}")),
            Err(_) => Err(format!("not a whole number; allowed {range}")),
        }
    }
}

/// `--threads`: a whole number in [1, the largest pool].
pub(crate) fn threads(text: &str) -> Result<u32, String> {
    whole::<u32>(1, crate::MAX_THREADS as u64)(text)
}

/// `--shards`: a whole number in [1, the most shards].
pub(crate) fn shards(text: &str) -> Result<usize, String> {
    whole::<usize>(1, MAX_SHARDS as u64)(text)
}

/// `--shard`: a whole number below the most shards (whether it is below `--shards` is
/// checked with both).
pub(crate) fn shard(text: &str) -> Result<usize, String> {
    whole::<usize>(0, MAX_SHARDS as u64 - 1)(text)
}

/// The range a check allows, in its own words: the first error it gives for the largest
/// finite numbers of either sign; "a finite number" if it accepts both.
fn allowed_by(check: impl Fn(f64) -> Result<(), InvalidParameter>) -> String {
    [f64::MAX, -f64::MAX]
        .into_iter()
        .find_map(|x| check(x).err())
        .map_or_else(|| "a finite number".to_string(), |e| e.allowed)
}

/// The range of the scene's `speed_rpm` (`--speed-rpm`).
pub(crate) fn speed_range() -> String {
    whirlmap_sweep::overrides::finite_range(&Scene::default(), "speed_rpm")
}

/// The range of the scene's `mu_dynamic` (`drop --mu`).
pub(crate) fn mu_range() -> String {
    whirlmap_sweep::overrides::finite_range(&Scene::default(), "mu_dynamic")
}

/// The range of a critical search's coefficients (`critical --mu`).
pub(crate) fn critical_mu_range() -> String {
    allowed_by(|mu| check_mus(&[mu]))
}

/// The range of a drop's duration (`--duration-s`).
pub(crate) fn duration_range() -> String {
    allowed_by(|d| {
        DropOptions {
            duration_s: d,
            ..Default::default()
        }
        .validate()
    })
}

/// The range of one field of a critical search's options, the others at their defaults.
fn critical_range(set: fn(&mut CriticalOptions, f64)) -> String {
    allowed_by(|x| {
        let mut o = CriticalOptions::default();
        set(&mut o, x);
        o.validate()
    })
}

/// The range of `critical --from`.
pub(crate) fn from_range() -> String {
    critical_range(|o, x| o.from_rpm = x)
}

/// The range of `critical --to`. The check states its lower bound as `--from`'s value (the
/// default's here), which the flag's name stands for.
pub(crate) fn to_range() -> String {
    let from = num(CriticalOptions::default().from_rpm);
    critical_range(|o, x| o.to_rpm = x).replacen(&from, "--from", 1)
}

/// The range of `critical --resolution-rpm`.
pub(crate) fn resolution_range() -> String {
    critical_range(|o, x| o.resolution_rpm = x)
}

/// The range of `critical --tol-rpm`. The check states its upper bound as
/// `--resolution-rpm`'s value (the default's here), which the flag's name stands for.
pub(crate) fn tol_range() -> String {
    let resolution = num(CriticalOptions::default().resolution_rpm);
    critical_range(|o, x| o.tol_rpm = x).replacen(&resolution, "--resolution-rpm", 1)
}

/// The range of `compare --force-rel` and `--power-rel` (both the same).
pub(crate) fn threshold_range() -> String {
    let bad = Thresholds {
        force_rel: f64::NAN,
        ..Thresholds::default()
    };
    match bad.validate() {
        Err(e) => e
            .split_once("allowed ")
            .map_or(e.clone(), |(_, r)| r.to_string()),
        Ok(()) => "a finite number".to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_that_is_not_a_number_is_refused_with_the_flags_range() {
        assert_eq!(number(mu_range)(" 0.25 "), Ok(0.25));
        assert_eq!(number(speed_range)("-3e3"), Ok(-3000.0));
        let zero = number(mu_range)("-0").unwrap();
        assert!(zero == 0.0 && zero.is_sign_positive());
        assert_eq!(
            number(mu_range)("abc").unwrap_err(),
            "not a number; allowed [0, 2]"
        );
        assert_eq!(
            number(speed_range)("fast").unwrap_err(),
            "not a number; allowed [-1e6, 1e6] r/min"
        );
        assert_eq!(
            number(duration_range)("1s").unwrap_err(),
            "not a number; allowed (0, 3600] s"
        );
        assert_eq!(
            number(critical_mu_range)("").unwrap_err(),
            "not a number; allowed [0, 2]"
        );
        assert_eq!(from_range(), "[0, 1e6) r/min");
        assert_eq!(resolution_range(), "[1, 1e5] r/min");
        assert!(threshold_range().starts_with("[0, inf)"));
    }

    #[test]
    fn a_bound_set_by_another_flag_is_named_by_that_flag() {
        assert!(
            to_range().starts_with("(--from, 1e6] r/min"),
            "{}",
            to_range()
        );
        assert!(
            tol_range().starts_with("[0.01, --resolution-rpm] r/min"),
            "{}",
            tol_range()
        );
    }

    #[test]
    fn whole_numbers_are_checked_against_their_range() {
        assert_eq!(threads("2"), Ok(2));
        assert_eq!(
            threads("0").unwrap_err(),
            format!("0 is out of range; allowed [1, {}]", crate::MAX_THREADS)
        );
        assert_eq!(
            threads("1.5").unwrap_err(),
            format!("not a whole number; allowed [1, {}]", crate::MAX_THREADS)
        );
        assert_eq!(
            threads("-1").unwrap_err(),
            format!("-1 is out of range; allowed [1, {}]", crate::MAX_THREADS)
        );
        assert!(threads("99999999999999999999999")
            .unwrap_err()
            .contains("out of range"));
        assert_eq!(shard("0"), Ok(0));
        assert!(shards("0").unwrap_err().contains("out of range"));
        assert_eq!(shards(&MAX_SHARDS.to_string()), Ok(MAX_SHARDS));
    }
}
