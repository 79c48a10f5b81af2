//! Embeds the commit this crate is built from (`WHIRLMAP_GIT_COMMIT`), for the results
//! manifests: `git rev-parse HEAD` at build time, or the `WHIRLMAP_GIT_COMMIT` environment
//! variable when set (a build outside a checkout), else `unknown`. Never fails the build.

use std::path::Path;
use std::process::Command;

fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git").args(args).output().ok()?;
    if !out.status.success() {
        return None;
    }
    let s = String::from_utf8(out.stdout).ok()?.trim().to_string();
    (!s.is_empty()).then_some(s)
}

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=WHIRLMAP_GIT_COMMIT");
    let commit = std::env::var("WHIRLMAP_GIT_COMMIT")
        .ok()
        .filter(|s| !s.trim().is_empty())
        .or_else(|| git(&["rev-parse", "HEAD"]))
        .unwrap_or_else(|| "unknown".to_string());
    println!("cargo:rustc-env=WHIRLMAP_GIT_COMMIT={commit}");
    // Rebuilt when HEAD moves: HEAD itself (a checkout of another branch or commit), the
    // branch it names (a new commit), and packed-refs (where a branch may live). Only files
    // that exist are named: a missing one would rerun this script on every build.
    let mut watch = vec![git(&["rev-parse", "--git-path", "HEAD"])];
    if let Some(branch) = git(&["symbolic-ref", "-q", "HEAD"]) {
        watch.push(git(&["rev-parse", "--git-path", &branch]));
    }
    watch.push(git(&["rev-parse", "--git-path", "packed-refs"]));
    for p in watch.into_iter().flatten() {
        if Path::new(&p).exists() {
            println!("cargo:rerun-if-changed={p}");
        }
    }
}
