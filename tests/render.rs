//! `whirlmap render DIR`: exit codes and the files it prints.

mod common;
use common::*;

use std::path::PathBuf;
use std::process::Command;

#[test]
fn render_draws_charts_and_reports_exit_codes() {
    // No points.jsonl: exit 2.
    let empty = temp_dir("empty");
    let out = whirlmap(&["render".as_ref(), empty.as_os_str()]);
    assert_eq!(out.status.code(), Some(2), "{out:?}");

    // A 2 x 2 grid with a torn last line: three charts as PNG and SVG.
    let dir = temp_dir("grid");
    let mut text = String::new();
    for (i, (s, m, class)) in [
        (2000.0, 0.1, "pendulum"),
        (4000.0, 0.1, "pendulum"),
        (2000.0, 0.2, "pendulum"),
        (4000.0, 0.2, "backward_whirl"),
    ]
    .iter()
    .enumerate()
    {
        text.push_str(&format!(
            "{{\"key\":\"k{i}\",\"index\":{i},\"inputs\":{{\"speed_rpm\":{s},\"mu\":{m}}},\
             \"status\":\"ok\",\"record\":{{\"class\":\"{class}\",\"max_contact_force_n\":{},\
             \"peak_heat_power_w\":{}}}}}\n",
            500.0 + s / 10.0,
            100.0 * m
        ));
    }
    text.push_str("{\"key\":\"k4\",\"inp");
    std::fs::write(dir.join("points.jsonl"), text).unwrap();
    let out = whirlmap(&["render".as_ref(), dir.as_os_str()]);
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert_eq!(stdout.lines().count(), 6, "{stdout}");
    for line in stdout.lines() {
        assert!(std::fs::metadata(line).unwrap().len() > 0, "{line}");
    }

    // charts/ cannot be created: exit 4.
    std::fs::remove_dir_all(dir.join("charts")).unwrap();
    std::fs::write(dir.join("charts"), "not a directory").unwrap();
    let out = whirlmap(&["render".as_ref(), dir.as_os_str()]);
    assert_eq!(out.status.code(), Some(4), "{out:?}");

    let _ = std::fs::remove_dir_all(&empty);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn design_charts_render_with_no_system_fonts() {
    // The committed paper records, redrawn in a process where fontconfig finds no font at all:
    // only the embedded DejaVu Sans can draw the labels.
    let dir = temp_dir("nofonts");
    let src = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("results/paper");
    for f in ["points.jsonl", "critical.json"] {
        std::fs::copy(src.join(f), dir.join(f)).unwrap();
    }
    let fc = dir.join("empty-fonts.conf");
    std::fs::write(&fc, "<?xml version=\"1.0\"?><!DOCTYPE fontconfig SYSTEM \"fonts.dtd\"><fontconfig></fontconfig>").unwrap();
    let empty = dir.join("no-fonts-here");
    std::fs::create_dir_all(&empty).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_whirlmap"))
        .arg("render")
        .arg(&dir)
        .env("FONTCONFIG_FILE", &fc)
        .env("FONTCONFIG_PATH", &empty)
        .env("HOME", &empty)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for name in [
        "fig5_max_force",
        "fig6_peak_power",
        "classes",
        "fig4_critical",
    ] {
        let png = std::fs::read(dir.join("charts").join(format!("{name}.png"))).unwrap();
        assert!(
            png.starts_with(b"\x89PNG\r\n\x1a\n") && png.len() > 5000,
            "{name}.png"
        );
        let svg = std::fs::read_to_string(dir.join("charts").join(format!("{name}.svg"))).unwrap();
        assert!(
            svg.contains("<svg") && svg.trim_end().ends_with("</svg>"),
            "{name}.svg"
        );
        assert!(svg.contains("r/min"), "{name}.svg lacks its axis unit");
    }
}

/// A sweep whose spec lists two charts gets those two and no third.
#[test]
fn a_sweep_draws_only_the_charts_its_spec_lists() {
    let dir = temp_dir("two-charts");
    let spec = dir.join("spec.json");
    std::fs::write(
        &spec,
        r#"{"name": "two-charts", "duration_s": 0.05,
            "axes": {"speed_rpm": [4000, 8000], "mu": [0.1, 0.4]},
            "charts": ["max_force", "classes"]}"#,
    )
    .unwrap();
    let out_dir = dir.join("out");
    let out = whirlmap(&[
        "sweep".as_ref(),
        spec.as_os_str(),
        "--out".as_ref(),
        out_dir.as_os_str(),
        "--no-progress".as_ref(),
    ]);
    assert!(out.status.success(), "{out:?}");
    let mut charts: Vec<String> = std::fs::read_dir(out_dir.join("charts"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    charts.sort();
    assert_eq!(
        charts,
        [
            "classes.png",
            "classes.svg",
            "fig5_max_force.png",
            "fig5_max_force.svg"
        ]
    );
    // render redraws the same two
    let out = whirlmap(&["render".as_ref(), out_dir.as_os_str()]);
    assert!(out.status.success(), "{out:?}");
    assert_eq!(
        std::fs::read_dir(out_dir.join("charts")).unwrap().count(),
        4
    );
}

#[test]
fn render_redraws_an_ensemble_and_says_an_adaptive_map_has_no_charts() {
    let results = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("results");
    // An adaptive map: no charts to draw, said plainly, exit 0, the folder left as it was.
    let adaptive = temp_dir("adaptive");
    std::fs::copy(
        results.join("adaptive-paper/adaptive.json"),
        adaptive.join("adaptive.json"),
    )
    .unwrap();
    let out = whirlmap(&["render".as_ref(), adaptive.as_os_str()]);
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(
        said.contains("no charts") && said.contains("adaptive"),
        "{said}"
    );
    assert!(!adaptive.join("charts").exists());

    // An ensemble: Fig. 4 with probability bands, as `whirlmap ensemble` drew it.
    let ensemble = temp_dir("ensemble");
    std::fs::copy(
        results.join("ensemble-paper/contours.json"),
        ensemble.join("contours.json"),
    )
    .unwrap();
    let out = whirlmap(&["render".as_ref(), ensemble.as_os_str()]);
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    for ext in ["png", "svg"] {
        let drawn = std::fs::read(ensemble.join(format!("charts/fig4_probability.{ext}"))).unwrap();
        let committed =
            std::fs::read(results.join(format!("ensemble-paper/charts/fig4_probability.{ext}")))
                .unwrap();
        assert!(
            drawn == committed,
            "fig4_probability.{ext} differs from the committed one"
        );
    }
}

/// Copies the folder `from` into `to`, recursively.
fn copy_tree(from: &std::path::Path, to: &std::path::Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            copy_tree(&p, &to.join(e.file_name()));
        } else {
            std::fs::copy(&p, to.join(e.file_name())).unwrap();
        }
    }
}

#[test]
fn render_leaves_a_committed_manifest_as_it_was() {
    // The charts come out the same, so the manifest (read and written as its typed form)
    // must come out byte for byte the same too, its keys in the order the run wrote them.
    let src = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("results/paper-radial");
    let dir = temp_dir("relist");
    copy_tree(&src, &dir);
    let out = whirlmap(&["render".as_ref(), dir.as_os_str()]);
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    let before = std::fs::read_to_string(src.join("manifest.json")).unwrap();
    let after = std::fs::read_to_string(dir.join("manifest.json")).unwrap();
    assert!(before == after, "render rewrote manifest.json");
}

#[test]
fn render_keeps_fig3_when_the_orbit_files_are_not_in_the_folder() {
    // A clone of the repository has the main job's charts and manifest but not its orbit
    // files (left out for their size): render redraws the rest, keeps Fig. 3 as the run drew
    // it, says why, and leaves the manifest as it was.
    let src = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("results/paper");
    let dir = temp_dir("no-orbits");
    copy_tree(&src, &dir);
    let _ = std::fs::remove_dir_all(dir.join("orbits"));
    let fig3 = dir.join("charts/fig3_orbits.png");
    let before = std::fs::read(&fig3).unwrap();
    let manifest = std::fs::read_to_string(dir.join("manifest.json")).unwrap();
    let out = whirlmap(&["render".as_ref(), dir.as_os_str()]);
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(
        stderr.contains("orbit file(s) the run wrote are not in") && stderr.contains("fig3_orbits"),
        "{stderr}"
    );
    assert_eq!(std::fs::read(&fig3).unwrap(), before, "Fig. 3 changed");
    assert!(dir.join("charts/fig3_orbits.svg").is_file());
    let after = std::fs::read_to_string(dir.join("manifest.json")).unwrap();
    assert!(manifest == after, "render rewrote manifest.json");
    let _ = std::fs::remove_dir_all(&dir);
}
