//! The recorded orbits of Fig. 3: one JSON file per panel in `orbits/`.

use crate::files::ORBITS_DIR;
use crate::read::{read_bytes, ReadError};
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::path::{Path, PathBuf};
use whirlmap_core::classify::OrbitClass;
use whirlmap_core::orbit::Orbit;

/// One recorded orbit, `orbits/NN_speed_mu.json`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct OrbitFile {
    /// Release speed (r/min).
    pub speed_rpm: f64,
    /// Friction coefficient.
    pub mu: f64,
    /// Orbit class (a class name).
    #[serde(default)]
    pub class: Value,
    /// The recorded orbit.
    pub orbit: Orbit,
}

impl OrbitFile {
    /// The file of a drop at `speed_rpm` and `mu` that settled into `class`.
    pub fn new(speed_rpm: f64, mu: f64, class: OrbitClass, orbit: Orbit) -> Self {
        Self {
            speed_rpm,
            mu,
            class: serde_json::to_value(class).expect("classes serialise"),
            orbit,
        }
    }

    /// The file's text: compact JSON with every object's keys in sorted order.
    pub fn to_json(&self) -> String {
        // Through a `Value`, whose objects keep their keys sorted.
        let v = serde_json::to_value(self).expect("orbits serialise");
        serde_json::to_string(&v).expect("orbits serialise")
    }

    /// The class's label, or the text recorded when it is not a known class.
    pub fn class_label(&self) -> String {
        match serde_json::from_value::<OrbitClass>(self.class.clone()) {
            Ok(c) => c.label().to_string(),
            Err(_) => match &self.class {
                Value::String(s) => s.replace('_', " "),
                Value::Null => "class unknown".to_string(),
                other => other.to_string(),
            },
        }
    }
}

/// Reads every `dir/orbits/*.json`, sorted by speed then friction; empty if there are none.
pub fn read_orbits(dir: &Path) -> Result<Vec<OrbitFile>, ReadError> {
    let odir = dir.join(ORBITS_DIR);
    let Ok(read) = std::fs::read_dir(&odir) else {
        return Ok(Vec::new());
    };
    let mut paths: Vec<PathBuf> = read
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("json"))
        })
        .collect();
    paths.sort();
    let mut out = Vec::new();
    for path in paths {
        let bytes = read_bytes(&path)?;
        let o: OrbitFile = serde_json::from_slice(&bytes).map_err(|e| ReadError::Parse {
            path: path.clone(),
            line: e.line(),
            message: e.to_string(),
        })?;
        out.push(o);
    }
    out.sort_by(|a, b| {
        a.speed_rpm
            .total_cmp(&b.speed_rpm)
            .then(a.mu.total_cmp(&b.mu))
    });
    Ok(out)
}
