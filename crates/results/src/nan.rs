//! Reading back what serde_json writes for values it cannot write as they are: a NaN is
//! written `null` (read back as NaN), and an `Option<Option<_>>` present as `null` is
//! `Some(None)`.

use serde::{Deserialize, Deserializer};

/// A number, or `null` for NaN.
pub(crate) fn null_as_nan<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

/// A field that is present (`Some`), its value `null` or not; absent is `None` through
/// `#[serde(default)]`.
pub(crate) fn present<'de, D: Deserializer<'de>, T: Deserialize<'de>>(
    d: D,
) -> Result<Option<Option<T>>, D::Error> {
    Ok(Some(Option::<T>::deserialize(d)?))
}
