//! `galvoplan linuxcnc-config`: a LinuxCNC machine configuration for a profile.

use anyhow::{bail, Context, Result};
use clap::Args;
use galvoplan::document::{write_atomic, MachineProfile};
use galvoplan::export::linuxcnc_config;
use std::path::PathBuf;

/// Arguments of `galvoplan linuxcnc-config`.
#[derive(Args, Debug)]
pub struct LinuxcncConfigArgs {
    /// Machine profile: a TOML file or a built-in name (seed000, small-field, linuxcnc, five-axis, rotary).
    #[arg(long, default_value = "linuxcnc")]
    profile: String,
    /// Folder to write the configuration into (made when missing; files of the same names in
    /// it are replaced, nothing else is touched).
    #[arg(long)]
    out: PathBuf,
}

/// Writes the configuration files and prints where.
pub fn run(a: &LinuxcncConfigArgs) -> Result<()> {
    let profile = MachineProfile::load(&a.profile)?;
    if a.out.exists() && !a.out.is_dir() {
        bail!("{}: is a file, not a folder", a.out.display());
    }
    std::fs::create_dir_all(&a.out)
        .with_context(|| format!("{}: cannot make the folder", a.out.display()))?;
    let profile_path = std::fs::canonicalize(&a.profile).ok();
    for f in linuxcnc_config(&profile) {
        let path = a.out.join(f.name);
        if profile_path.is_some() && std::fs::canonicalize(&path).ok() == profile_path {
            bail!(
                "{}: is the profile itself; choose another folder",
                path.display()
            );
        }
        write_atomic(&path, f.text.as_bytes())
            .with_context(|| format!("{}: cannot write", path.display()))?;
        if f.executable {
            set_executable(&path)?;
        }
    }
    let var = a.out.join("galvoplan.var");
    if !var.exists() {
        write_atomic(&var, b"").with_context(|| format!("{}: cannot write", var.display()))?;
    }
    println!(
        "galvoplan: LinuxCNC configuration for '{}' in {} (run: linuxcnc {}/galvoplan.ini)",
        profile.name,
        a.out.display(),
        a.out.display()
    );
    Ok(())
}

#[cfg(unix)]
fn set_executable(path: &std::path::Path) -> Result<()> {
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o755))
        .with_context(|| format!("{}: cannot make it executable", path.display()))
}

#[cfg(not(unix))]
fn set_executable(_: &std::path::Path) -> Result<()> {
    Ok(())
}
