//! Outputs never destroy inputs: an export is refused when it would write over a file the job
//! was read from (artwork, project, pens, profile), or over another output of the same run.

use std::path::{Path, PathBuf};
use thiserror::Error;

/// An output that would overwrite an input or another output.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum OutputClash {
    /// The output is one of the job's inputs.
    #[error("{output}: refusing to write the {what} over {input}, which this job was read from; choose another name")]
    OverInput {
        /// What the output is (`G-code`, `report`, …).
        what: String,
        /// The output path.
        output: String,
        /// The input it would overwrite.
        input: String,
    },
    /// Two outputs of one run are the same file.
    #[error("{output}: the {what} and the {other} would be written to the same file")]
    Twice {
        /// The first output's kind.
        what: String,
        /// The second output's kind.
        other: String,
        /// The path.
        output: String,
    },
}

/// The file a path names: canonical when it (or its folder) exists, so that `./a.svg`,
/// `a.svg` and a symbolic link to it compare equal.
fn identity(p: &Path) -> PathBuf {
    if let Ok(c) = p.canonicalize() {
        return c;
    }
    let parent = match p.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    match (parent.canonicalize(), p.file_name()) {
        (Ok(d), Some(name)) => d.join(name),
        _ => p.to_path_buf(),
    }
}

/// Checks that no output (kind, path) is one of `inputs` or another output.
pub fn check_outputs(inputs: &[&Path], outputs: &[(&str, &Path)]) -> Result<(), OutputClash> {
    let inputs: Vec<(PathBuf, &Path)> = inputs.iter().map(|p| (identity(p), *p)).collect();
    let mut seen: Vec<(PathBuf, &str)> = Vec::new();
    for &(what, path) in outputs {
        let id = identity(path);
        if let Some((_, input)) = inputs.iter().find(|(i, _)| *i == id) {
            return Err(OutputClash::OverInput {
                what: what.into(),
                output: path.display().to_string(),
                input: input.display().to_string(),
            });
        }
        if let Some((_, other)) = seen.iter().find(|(s, _)| *s == id) {
            return Err(OutputClash::Twice {
                what: (*other).into(),
                other: what.into(),
                output: path.display().to_string(),
            });
        }
        seen.push((id, what));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_input_or_a_second_output_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let art = dir.path().join("art.svg");
        std::fs::write(&art, "<svg/>").unwrap();
        let same = dir.path().join(".").join("art.svg");
        let e = check_outputs(&[&art], &[("G-code", &same)]).unwrap_err();
        assert!(matches!(e, OutputClash::OverInput { .. }), "{e}");
        assert!(e.to_string().contains("refusing"), "{e}");
        let out = dir.path().join("out.gcode");
        assert!(check_outputs(&[&art], &[("G-code", &out)]).is_ok());
        let e = check_outputs(&[&art], &[("G-code", &out), ("report", &out)]).unwrap_err();
        assert!(matches!(e, OutputClash::Twice { .. }), "{e}");
    }
}
