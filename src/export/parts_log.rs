//! The parts log: one CSV row per part marked (date-time, program, part, serial, what its texts
//! said), appended once the program is written, so that every serial handed out is on record.

use crate::document::PartRecord;
use std::io::Write;
use std::path::Path;

/// The log's header row.
pub const PARTS_LOG_HEADER: &str = "date_time,program,part,serial,contents";

/// The rows of `parts` (with the header when `header`), as CSV text; the texts of a part, then
/// its codes' contents, are joined by ` | ` in its `contents`.
pub fn parts_log_rows(program: &str, parts: &[PartRecord], when: &str, header: bool) -> String {
    let mut w = csv::WriterBuilder::new()
        .has_headers(false)
        .from_writer(Vec::new());
    let mut out = String::new();
    if header {
        out.push_str(PARTS_LOG_HEADER);
        out.push('\n');
    }
    for p in parts {
        // writing to a Vec cannot fail
        let _ = w.write_record([
            when,
            program,
            &p.part.to_string(),
            &p.serial.to_string(),
            &p.texts
                .iter()
                .chain(&p.codes)
                .cloned()
                .collect::<Vec<_>>()
                .join(" | "),
        ]);
    }
    let _ = w.flush();
    out.push_str(&String::from_utf8_lossy(w.get_ref()));
    out
}

/// Appends the rows of `parts` to the log at `path` (created with its header when new or
/// empty) in one write.
pub fn append_parts_log(
    path: &Path,
    program: &str,
    parts: &[PartRecord],
    when: String,
) -> std::io::Result<()> {
    let mut f = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)?;
    let new = f.metadata()?.len() == 0;
    f.write_all(parts_log_rows(program, parts, &when, new).as_bytes())?;
    f.sync_all()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_quote_what_needs_it() {
        let p = PartRecord {
            part: 2,
            cell: 3,
            col: 3,
            row: 1,
            position_mm: [80.0, 0.0],
            serial: 1002,
            texts: vec!["SN 01002".into(), "lot \"A\", 7".into()],
            codes: vec!["GP01002".into()],
        };
        let rows = parts_log_rows("tray.gcode", &[p], "2026-12-07T14:30:00", true);
        assert_eq!(
            rows,
            "date_time,program,part,serial,contents\n2026-12-07T14:30:00,tray.gcode,2,1002,\"SN 01002 | lot \"\"A\"\", 7 | GP01002\"\n"
        );
    }
}
