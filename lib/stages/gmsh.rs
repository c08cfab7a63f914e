//! The optional `gmsh` stage: runs the gmsh executable on a `.geo` file.

use std::path::{Path, PathBuf};
use std::process::Command;

use super::StageRunError;
use crate::format::stage::temp_path;

/// MSH flavours gmsh can write.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum MshFlavour {
    Msh22,
    #[default]
    Msh41,
}

/// The gmsh executable: `$GMSH` if set, else `gmsh` on `PATH`.
pub fn find_gmsh() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("GMSH") {
        return Some(PathBuf::from(p));
    }
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path).map(|d| d.join("gmsh")).find(|p| p.is_file())
}

/// Mesh `geo` in 3D into `output` (written atomically through a temporary file).
pub fn run_gmsh(geo: &Path, output: &Path, flavour: MshFlavour, binary: bool) -> Result<(), StageRunError> {
    let exe = find_gmsh().ok_or_else(|| {
        StageRunError::Tool(format!(
            "gmsh is not installed (not on PATH and $GMSH unset), so {} cannot be meshed; install it (`pip install gmsh` puts `gmsh` in the venv's bin/) or use the committed .msh",
            geo.display()
        ))
    })?;
    if !geo.is_file() {
        return Err(StageRunError::Usage(format!("{}: no such .geo file", geo.display())));
    }
    let tmp = temp_path(output).with_extension("msh");
    let fmt = match flavour {
        MshFlavour::Msh22 => "msh22",
        MshFlavour::Msh41 => "msh41",
    };
    let mut cmd = Command::new(&exe);
    cmd.arg(geo).arg("-3").arg("-format").arg(fmt).arg("-o").arg(&tmp);
    if binary {
        cmd.arg("-bin");
    }
    let out = cmd.output().map_err(|e| StageRunError::Tool(format!("cannot run {}: {e}", exe.display())))?;
    if !out.status.success() || !tmp.is_file() {
        let _ = std::fs::remove_file(&tmp);
        let log = String::from_utf8_lossy(&out.stderr).to_string() + &String::from_utf8_lossy(&out.stdout);
        let errors: Vec<&str> = log.lines().filter(|l| l.contains("Error")).take(10).collect();
        return Err(StageRunError::Usage(format!("gmsh failed on {}: {}", geo.display(), if errors.is_empty() { log.trim().to_string() } else { errors.join("\n") })));
    }
    std::fs::rename(&tmp, output).map_err(|e| StageRunError::Tool(format!("{}: cannot rename the temporary mesh onto it: {e}", output.display())))
}
