//! The build a result was made with: the package version and the commit the binary was built
//! from (embedded at compile time by `build.rs`, not read from the repository the command
//! happens to run in). Manifests record both; a resume and a merge compare them.

/// The whirlmap package version of this build.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// The commit this build was made from (`git rev-parse HEAD` at build time), or `unknown`
/// when it was built outside a git checkout without `WHIRLMAP_GIT_COMMIT` set.
pub const GIT_COMMIT: &str = env!("WHIRLMAP_GIT_COMMIT");

/// `VERSION (commit GIT_COMMIT)`, for `whirlmap --version` and messages.
pub const DESCRIPTION: &str = concat!(
    env!("CARGO_PKG_VERSION"),
    " (commit ",
    env!("WHIRLMAP_GIT_COMMIT"),
    ")"
);

/// `version (commit c)` for a recorded build, as [`DESCRIPTION`] describes this one.
pub fn describe(version: &str, commit: &str) -> String {
    format!("{version} (commit {commit})")
}

/// The recorded build (`version`, `commit`; `None` where a manifest has no such key),
/// described as [`describe`] does, when it is not this one; `None` when it is.
pub fn other_build(version: Option<&str>, commit: Option<&str>) -> Option<String> {
    (version != Some(VERSION) || commit != Some(GIT_COMMIT))
        .then(|| describe(version.unwrap_or("?"), commit.unwrap_or("?")))
}
