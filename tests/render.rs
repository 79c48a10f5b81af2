//! `whirlmap render DIR`: exit codes and the files it prints.

use std::path::PathBuf;
use std::process::Command;

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("whirlmap-render-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn whirlmap(args: &[&std::ffi::OsStr]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_whirlmap"))
        .args(args)
        .output()
        .unwrap()
}

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
