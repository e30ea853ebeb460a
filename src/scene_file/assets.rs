//! Where a scene's mesh and image files may come from.
//!
//! A scene names files by path, so a scene from elsewhere (a farm's queue, a download) could
//! pull any readable file on the host into its output. By default the files of a scene read
//! from disk must resolve, after symlinks are followed, inside its asset root: the parent of
//! the scene's folder (the shipped scenes use `../assets/…`). Absolute paths are refused.
//! The command line moves the root with `--asset-root DIR` or lifts the check with
//! `--allow-any-path`.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// Which asset paths a scene may use.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum AssetPolicy {
    /// Any path, absolute or climbing out with `..`.
    Any,
    /// Relative paths that resolve inside this folder.
    Root(PathBuf),
}

/// The command line's choice for every scene loaded from a file, set once at start-up.
static OVERRIDE: OnceLock<AssetPolicy> = OnceLock::new();

/// Makes `policy` the one used for every scene file loaded after it (instead of each scene's
/// default root). The command line calls it once, for `--asset-root` or `--allow-any-path`;
/// later calls are ignored.
pub fn set_policy(policy: AssetPolicy) {
    let _ = OVERRIDE.set(policy);
}

impl AssetPolicy {
    /// The policy for the scene file at `scene`: the one set by [`set_policy`], else the
    /// parent of the scene's folder as the root.
    pub fn for_scene(scene: &Path) -> AssetPolicy {
        if let Some(p) = OVERRIDE.get() {
            return p.clone();
        }
        let file = scene.canonicalize().unwrap_or_else(|_| scene.to_path_buf());
        let dir = file.parent().unwrap_or(Path::new("."));
        AssetPolicy::Root(dir.parent().unwrap_or(dir).to_path_buf())
    }

    /// Checks the asset path `rel` (as written in the scene) of a scene in `scene_dir`.
    /// A file that does not exist passes: reading it reports that.
    pub fn check(&self, scene_dir: &Path, rel: &str) -> Result<(), String> {
        let AssetPolicy::Root(root) = self else {
            return Ok(());
        };
        let p = Path::new(rel);
        if p.is_absolute() {
            return Err(format!(
                "absolute asset path '{}' refused: write it relative to the scene file (or \
                 run with --allow-any-path)",
                rel.escape_debug()
            ));
        }
        let Ok(file) = scene_dir.join(p).canonicalize() else {
            return Ok(());
        };
        let root = root.canonicalize().unwrap_or_else(|_| root.clone());
        if file.starts_with(&root) {
            Ok(())
        } else {
            Err(format!(
                "'{}' resolves to '{}', outside the asset root '{}' (the scene folder's \
                 parent; --asset-root DIR moves it, --allow-any-path lifts the check)",
                rel.escape_debug(),
                file.display(),
                root.display()
            ))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_paths_inside_the_root_pass_and_others_do_not() {
        let d = tempfile::tempdir().unwrap();
        let root = d.path().join("project");
        let scenes = root.join("scenes");
        std::fs::create_dir_all(&scenes).unwrap();
        std::fs::create_dir_all(root.join("assets")).unwrap();
        std::fs::write(root.join("assets/a.obj"), "").unwrap();
        std::fs::write(d.path().join("secret.png"), "").unwrap();
        let policy = AssetPolicy::Root(root.clone());
        assert_eq!(policy.check(&scenes, "../assets/a.obj"), Ok(()));
        // Missing files are the loader's to report.
        assert_eq!(policy.check(&scenes, "../assets/none.obj"), Ok(()));
        let out = policy.check(&scenes, "../../secret.png").unwrap_err();
        assert!(out.contains("outside the asset root"), "{out}");
        let abs = root.join("assets/a.obj");
        let out = policy.check(&scenes, abs.to_str().unwrap()).unwrap_err();
        assert!(out.contains("absolute asset path"), "{out}");
        // A symlink inside the root that leads out of it is followed.
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(d.path().join("secret.png"), root.join("assets/l.png"))
                .unwrap();
            assert!(policy.check(&scenes, "../assets/l.png").is_err());
        }
        assert_eq!(AssetPolicy::Any.check(&scenes, "../../secret.png"), Ok(()));
        assert_eq!(
            AssetPolicy::Any.check(&scenes, abs.to_str().unwrap()),
            Ok(())
        );
    }
}
