//! Orbit charts render to PNG and SVG, including on a machine with no system fonts.
//!
//! The no-fonts check re-runs this test binary as a child process (selected by
//! [`CHILD_ENV`]) with fontconfig pointed at an empty configuration and empty font paths,
//! and checks the child still writes a PNG and a well-formed SVG.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{SystemTime, UNIX_EPOCH};

use whirlmap_core::orbit::{Orbit, OrbitSample};
use whirlmap_plot::render::{draw_orbit, ImageFormat, RenderError};

/// When set, [`child_renders_into_dir`] renders into the directory it names.
const CHILD_ENV: &str = "WHIRLMAP_RENDER_CHILD_DIR";
/// When set, the parent tests keep their output directory (to look at the charts).
const KEEP_ENV: &str = "WHIRLMAP_KEEP_RENDER_OUTPUT";

const PNG_SIGNATURE: [u8; 8] = [0x89, b'P', b'N', b'G', b'\r', b'\n', 0x1a, b'\n'];

/// A fresh, unique directory under the system temp dir.
fn unique_dir(tag: &str) -> PathBuf {
    let nanos = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_nanos())
        .unwrap_or(0);
    let dir = std::env::temp_dir().join(format!(
        "whirlmap-render-{tag}-{}-{nanos}",
        std::process::id()
    ));
    std::fs::create_dir_all(&dir).expect("create temp dir");
    dir
}

fn cleanup(dir: &Path) {
    if std::env::var_os(KEEP_ENV).is_some() {
        eprintln!("charts kept in {}", dir.display());
    } else {
        let _ = std::fs::remove_dir_all(dir);
    }
}

/// A drop-like orbit inside a 150 µm clearance: the centre falls, bounces with decaying
/// amplitude, then settles into a damped pendulum swing at the bottom of the race, with
/// force spikes at each impact.
fn synthetic_orbit(n: usize) -> Orbit {
    let clearance = 150e-6;
    let duration = 0.2;
    let samples = (0..n)
        .map(|i| {
            let t = duration * i as f64 / (n - 1) as f64;
            let decay = (-t / 0.05).exp();
            let angle = -std::f64::consts::FRAC_PI_2 + 1.2 * decay * (2.0 * 40.0 * t).sin();
            let radius = clearance * (1.0 - 0.6 * decay * (2.0 * 120.0 * t).cos().abs());
            let bounce = (2.0 * 120.0 * t).cos().abs();
            let force = if bounce > 0.97 {
                3000.0 * decay * (bounce - 0.97) / 0.03
            } else {
                0.0
            } + 40.0 * (1.0 - decay);
            OrbitSample {
                t_s: t,
                x_rel_m: radius * angle.cos(),
                y_rel_m: radius * angle.sin(),
                contact_force_n: force,
                ..Default::default()
            }
        })
        .collect();
    Orbit {
        clearance_m: clearance,
        samples,
    }
}

fn assert_png(path: &Path, min_len: usize) {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("read {}: {e}", path.display()));
    assert!(
        bytes.starts_with(&PNG_SIGNATURE),
        "{} is not a PNG",
        path.display()
    );
    assert!(
        bytes.len() > min_len,
        "{} is only {} bytes",
        path.display(),
        bytes.len()
    );
}

fn assert_svg(path: &Path) -> String {
    let text =
        std::fs::read_to_string(path).unwrap_or_else(|e| panic!("read {}: {e}", path.display()));
    let open = text.find("<svg").expect("no <svg element");
    let close = text.rfind("</svg>").expect("no </svg> end tag");
    assert!(open < close, "malformed SVG");
    assert!(text[close..].trim() == "</svg>", "content after </svg>");
    for label in ["x (µm)", "y (µm)", "time (ms)", "contact force (N)"] {
        assert!(text.contains(label), "SVG lacks axis label {label:?}");
    }
    text
}

#[test]
fn orbit_renders_png_and_svg() {
    let dir = unique_dir("orbit");
    let orbit = synthetic_orbit(4000);
    let png = dir.join("orbit.png");
    let svg = dir.join("orbit.SVG");
    draw_orbit(&png, "Synthetic drop, 150 µm clearance", &orbit).expect("png");
    draw_orbit(&svg, "Synthetic drop, 150 µm clearance", &orbit).expect("svg");
    assert_png(&png, 5 * 1024);
    let text = assert_svg(&svg);
    assert!(text.contains("Synthetic drop"), "SVG lacks the title");
    cleanup(&dir);
}

#[test]
fn long_orbit_is_decimated_and_renders() {
    let dir = unique_dir("long");
    let orbit = synthetic_orbit(200_000);
    let png = dir.join("long.png");
    let svg = dir.join("long.svg");
    draw_orbit(&png, "200k samples", &orbit).expect("png");
    draw_orbit(&svg, "200k samples", &orbit).expect("svg");
    assert_png(&png, 5 * 1024);
    let text = assert_svg(&svg);
    // Decimated to at most 20k points per series: well under 200k coordinate pairs.
    assert!(text.len() < 2_000_000, "SVG is {} bytes", text.len());
    cleanup(&dir);
}

#[test]
fn empty_and_non_finite_orbits_still_render() {
    let dir = unique_dir("degenerate");
    let empty = Orbit {
        clearance_m: 150e-6,
        samples: Vec::new(),
    };
    draw_orbit(&dir.join("empty.png"), "empty", &empty).expect("empty png");
    assert_png(&dir.join("empty.png"), 5 * 1024);
    draw_orbit(&dir.join("empty.svg"), "empty", &empty).expect("empty svg");
    assert_svg(&dir.join("empty.svg"));

    let mut bad = synthetic_orbit(500);
    bad.samples[10].x_rel_m = f64::NAN;
    bad.samples[20].contact_force_n = f64::INFINITY;
    bad.samples[30].t_s = f64::NEG_INFINITY;
    bad.clearance_m = f64::NAN;
    draw_orbit(&dir.join("nan.png"), "non-finite", &bad).expect("nan png");
    assert_png(&dir.join("nan.png"), 5 * 1024);

    let all_nan = Orbit {
        clearance_m: -1.0,
        samples: vec![
            OrbitSample {
                t_s: f64::NAN,
                x_rel_m: f64::NAN,
                y_rel_m: f64::NAN,
                contact_force_n: f64::NAN,
                ..Default::default()
            };
            3
        ],
    };
    draw_orbit(&dir.join("all_nan.svg"), "", &all_nan).expect("all-NaN svg");
    assert_svg(&dir.join("all_nan.svg"));

    // A blown-up solution: huge but finite values must not panic or hang.
    let mut huge = synthetic_orbit(50);
    huge.samples[25].x_rel_m = 1e300;
    huge.samples[26].y_rel_m = -f64::MAX;
    huge.samples[27].contact_force_n = f64::MAX;
    huge.samples[28].t_s = 1e300;
    draw_orbit(&dir.join("huge.png"), "huge", &huge).expect("huge png");
    assert_png(&dir.join("huge.png"), 5 * 1024);
    cleanup(&dir);
}

#[test]
fn unsupported_extension_is_a_typed_error() {
    let dir = unique_dir("ext");
    let orbit = synthetic_orbit(100);
    for name in ["orbit.jpg", "orbit", "orbit.png.bak"] {
        let path = dir.join(name);
        match draw_orbit(&path, "t", &orbit) {
            Err(RenderError::UnsupportedExtension { path: p }) => assert_eq!(p, path),
            other => panic!("{name}: expected UnsupportedExtension, got {other:?}"),
        }
        assert!(!path.exists(), "{name} was written");
    }
    let err = ImageFormat::from_path(Path::new("x.gif")).unwrap_err();
    assert!(err.to_string().contains(".png or .svg"), "{err}");
    cleanup(&dir);
}

#[test]
fn missing_directory_is_a_typed_error() {
    let dir = unique_dir("missing").join("does-not-exist");
    let err = draw_orbit(&dir.join("o.png"), "t", &synthetic_orbit(100)).unwrap_err();
    assert!(matches!(err, RenderError::Draw { .. }), "{err:?}");
    assert!(err.to_string().contains("does-not-exist"), "{err}");
    let _ = std::fs::remove_dir_all(dir.parent().unwrap());
}

/// Child half of [`renders_without_system_fonts`]: a no-op unless [`CHILD_ENV`] is set.
#[test]
fn child_renders_into_dir() {
    let Some(dir) = std::env::var_os(CHILD_ENV) else {
        return;
    };
    let dir = PathBuf::from(dir);
    let orbit = synthetic_orbit(2000);
    draw_orbit(&dir.join("child.png"), "no system fonts", &orbit).expect("child png");
    draw_orbit(&dir.join("child.svg"), "no system fonts", &orbit).expect("child svg");
}

#[test]
fn renders_without_system_fonts() {
    if std::env::var_os(CHILD_ENV).is_some() {
        return; // we are the child; don't recurse
    }
    let dir = unique_dir("nofonts");
    let fc_file = dir.join("empty-fonts.conf");
    std::fs::write(
        &fc_file,
        r#"<?xml version="1.0"?><!DOCTYPE fontconfig SYSTEM "fonts.dtd"><fontconfig></fontconfig>"#,
    )
    .unwrap();
    let empty = dir.join("empty");
    std::fs::create_dir_all(&empty).unwrap();

    let exe = std::env::current_exe().expect("test binary path");
    let output = Command::new(exe)
        .args(["child_renders_into_dir", "--exact", "--test-threads=1"])
        .env(CHILD_ENV, &dir)
        .env("FONTCONFIG_FILE", &fc_file)
        .env("FONTCONFIG_PATH", &empty)
        .env("FONTCONFIG_SYSROOT", &empty)
        .env("XDG_DATA_HOME", &empty)
        .env("XDG_DATA_DIRS", &empty)
        .env("XDG_CONFIG_HOME", &empty)
        .env("HOME", &empty)
        .output()
        .expect("spawn child test process");
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "child failed: {}\n{stdout}\n{}",
        output.status,
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(
        stdout.contains("1 passed"),
        "child did not run the render test:\n{stdout}"
    );
    assert_png(&dir.join("child.png"), 5 * 1024);
    assert_svg(&dir.join("child.svg"));
    cleanup(&dir);
}
