//! The layering of the workspace, read from the one place it is written: the path entries of
//! `[workspace.dependencies]` in the root `Cargo.toml`, in order (bottom first), then `xtask`
//! on top. A crate may depend only on crates before it; `xtask/tests/layering.rs` checks every
//! edge of `cargo metadata` against this order.

/// The root manifest, compiled in so `cargo xtask layers` answers without the source tree.
const WORKSPACE_MANIFEST: &str = include_str!("../../Cargo.toml");

/// The workspace's crates, bottom first.
pub fn layers() -> Vec<&'static str> {
    let mut out = parse(WORKSPACE_MANIFEST);
    out.push("xtask");
    out
}

/// The names of the `name = { path = "..." }` entries of `[workspace.dependencies]`, in order.
fn parse(manifest: &'static str) -> Vec<&'static str> {
    let mut in_section = false;
    let mut out = Vec::new();
    for line in manifest.lines().map(str::trim) {
        if line.starts_with('[') {
            in_section = line == "[workspace.dependencies]";
        } else if in_section
            && line.contains("path = ")
            && let Some((name, _)) = line.split_once('=')
        {
            out.push(name.trim());
        }
    }
    out
}

#[cfg(test)]
mod tests {
    #[test]
    fn reads_the_path_entries_in_order() {
        let toml = "[workspace]\nmembers = [\"crates/*\"]\n[workspace.dependencies]\n\
                    # ours\nb = { path = \"crates/b\" }\na = { path = \"crates/a\" }\n\
                    serde = \"1\"\n[profile.dev]\nopt-level = 1\n";
        assert_eq!(super::parse(toml), ["b", "a"]);
        let all = super::layers();
        assert_eq!(all.first(), Some(&"stdx"));
        assert_eq!(all.last(), Some(&"xtask"));
    }
}
