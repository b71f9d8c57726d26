//! Recording runs with rerun (feature `rerun`): geometry, scan fields, the planned path and the
//! GA's convergence, written to an `.rrd` file without opening a viewer.

use crate::document::{Geometry, Plan, ScanField};
use crate::geom::Pt;
use crate::job::RunRecorder;
use thiserror::Error;

/// The recording could not be created or written.
#[derive(Debug, Error)]
#[error("{file}: cannot write the rerun recording: {msg}")]
pub struct RecordError {
    /// The file.
    pub file: String,
    /// The cause.
    pub msg: String,
}

/// A [`RunRecorder`] writing to an `.rrd` file. The recorder's calls cannot fail (a stage
/// must not stop for its recording); the first logging error is kept and reported by
/// [`RerunRecorder::finish`].
pub struct RerunRecorder {
    rec: rerun::RecordingStream,
    file: String,
    first_error: std::sync::Mutex<Option<String>>,
}

fn xy(p: crate::geom::Pt) -> [f32; 2] {
    [p.x as f32, p.y as f32]
}

impl RerunRecorder {
    /// Creates the recording file.
    pub fn create(path: &std::path::Path) -> Result<Self, RecordError> {
        let file = path.display().to_string();
        let rec = rerun::RecordingStreamBuilder::new("galvoplan")
            .save(path)
            .map_err(|e| RecordError {
                file: file.clone(),
                msg: e.to_string(),
            })?;
        Ok(Self {
            rec,
            file,
            first_error: std::sync::Mutex::new(None),
        })
    }

    /// Flushes everything to disk; reports the first error of the recording, if any.
    pub fn finish(&self) -> Result<(), RecordError> {
        let error = |msg: String| RecordError {
            file: self.file.clone(),
            msg,
        };
        self.rec
            .flush_blocking()
            .map_err(|e| error(e.to_string()))?;
        let first = self
            .first_error
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .take();
        match first {
            Some(msg) => Err(error(msg)),
            None => Ok(()),
        }
    }

    /// Keeps the first error of a logging call.
    fn keep<E: std::fmt::Display>(&self, what: &str, r: Result<(), E>) {
        if let Err(e) = r {
            let mut first = self
                .first_error
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner);
            first.get_or_insert_with(|| format!("{what}: {e}"));
        }
    }
}

impl RunRecorder for RerunRecorder {
    fn geometry(&self, geometries: &[Geometry]) {
        let strips: Vec<rerun::LineStrip2D> = geometries
            .iter()
            .map(|g| {
                let mut pts: Vec<[f32; 2]> = g.points.iter().map(|&p| xy(p)).collect();
                if g.closed {
                    if let Some(&f) = pts.first() {
                        pts.push(f);
                    }
                }
                rerun::LineStrip2D::from_iter(pts)
            })
            .collect();
        self.keep(
            "log",
            self.rec.log_static(
                "artwork",
                &rerun::LineStrips2D::new(strips).with_colors([rerun::Color::from_rgb(40, 40, 40)]),
            ),
        );
    }

    fn fields(&self, fields: &[ScanField]) {
        let centers: Vec<[f32; 2]> = fields.iter().map(|f| xy(f.center)).collect();
        let sizes: Vec<[f32; 2]> = fields
            .iter()
            .map(|f| [f.size[0] as f32, f.size[1] as f32])
            .collect();
        // numbered 1…n in placement order, as the canvas numbers them before a plan
        let labels: Vec<String> = (1..=fields.len()).map(|k| format!("field {k}")).collect();
        self.keep(
            "log",
            self.rec.log_static(
                "fields",
                &rerun::Boxes2D::from_centers_and_sizes(centers, sizes)
                    .with_labels(labels)
                    .with_colors([rerun::Color::from_rgb(59, 130, 246)]),
            ),
        );
    }

    fn plan(&self, plan: &Plan, marks: &[&[Pt]]) {
        let ends: Vec<(Pt, Pt)> = marks
            .iter()
            .filter_map(|pts| Some((*pts.first()?, *pts.last()?)))
            .collect();
        let marks: Vec<rerun::LineStrip2D> = marks
            .iter()
            .map(|pts| rerun::LineStrip2D::from_iter(pts.iter().map(|&p| xy(p))))
            .collect();
        let idle: Vec<rerun::LineStrip2D> = ends
            .windows(2)
            .map(|w| rerun::LineStrip2D::from_iter([xy(w[0].1), xy(w[1].0)]))
            .collect();
        let base: Vec<[f32; 2]> = plan.fields.iter().map(|f| xy(f.center)).collect();
        let root = format!("plans/{}", plan.name);
        self.keep(
            "log",
            self.rec.log_static(
                format!("{root}/marks"),
                &rerun::LineStrips2D::new(marks).with_colors([rerun::Color::from_rgb(0, 0, 0)]),
            ),
        );
        self.keep(
            "log",
            self.rec.log_static(
                format!("{root}/idle"),
                &rerun::LineStrips2D::new(idle).with_colors([rerun::Color::from_rgb(220, 38, 38)]),
            ),
        );
        self.keep(
            "log",
            self.rec.log_static(
                format!("{root}/base_path"),
                &rerun::LineStrips2D::new([rerun::LineStrip2D::from_iter(base)])
                    .with_colors([rerun::Color::from_rgb(22, 163, 74)]),
            ),
        );
        self.keep("flush", self.rec.flush_blocking());
    }

    fn generation(&self, generation: usize, best: f64, mean: f64) {
        self.rec.set_time_sequence("generation", generation as i64);
        self.keep(
            "log",
            self.rec.log("hga/best", &rerun::Scalars::single(best)),
        );
        self.keep(
            "log",
            self.rec.log("hga/mean", &rerun::Scalars::single(mean)),
        );
    }
}
