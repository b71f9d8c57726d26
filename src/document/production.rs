//! Production jobs: one part repeated over a tray, each part with its own serial number, date
//! and data (plain data and the text-field language; the tray is expanded into one job by
//! `crate::tray`, which shapes the texts).
//!
//! * A [`Tray`] repeats the part `cols × rows` times at a pitch from the part's placement. Cells
//!   are numbered row by row from the top-left, from 1 (what `--skip` names); the parts are
//!   numbered over the cells that are marked, row by row or serpentine ([`Numbering`]).
//! * A [`TextTemplate`] is a text of the artwork holding fields (`SN {serial:05}`), kept instead
//!   of its glyph outlines and shaped per part with the part's [`PartValues`].
//! * Fields: `{serial}`, `{serial:05}` (zero-padded to 5), `{part}`, `{row}`, `{col}`,
//!   `{date}` / `{date:%Y-%m-%d}`, `{time}` / `{time:%H:%M}` (strftime), `{csv:COLUMN}`;
//!   `{{` and `}}` write a brace.

use crate::geom::Pt;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;
use thiserror::Error;

/// Most cells a tray may have (a 100 × 100 fixture): more is not a tray.
pub const MAX_CELLS: u32 = 10_000;
/// Widest zero-padding a serial field may ask for.
pub const MAX_SERIAL_WIDTH: usize = 32;

/// How the marked cells are numbered.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Numbering {
    /// Row by row from the top-left, each row left to right.
    #[default]
    Rows,
    /// Row by row from the top-left, every other row right to left.
    Serpentine,
}

impl fmt::Display for Numbering {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Numbering::Rows => "rows",
            Numbering::Serpentine => "serpentine",
        })
    }
}

impl FromStr for Numbering {
    type Err = ProductionError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "rows" => Ok(Numbering::Rows),
            "serpentine" => Ok(Numbering::Serpentine),
            _ => Err(ProductionError::Syntax {
                what: "--numbering",
                text: s.into(),
                form: "rows or serpentine",
            }),
        }
    }
}

/// The tray: the part repeated `cols × rows` times, `pitch_mm` apart, some cells left out.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Tray {
    /// Columns (x).
    pub cols: u32,
    /// Rows (y, downwards).
    pub rows: u32,
    /// Distance between neighbouring parts in x and y, mm.
    pub pitch_mm: [f64; 2],
    /// Cells left out (broken fixture positions): cell numbers, row by row from 1.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub skip: Vec<u32>,
    /// How the marked cells are numbered.
    #[serde(default)]
    pub numbering: Numbering,
}

impl Default for Tray {
    fn default() -> Self {
        Self {
            cols: 1,
            rows: 1,
            pitch_mm: [0.0, 0.0],
            skip: Vec::new(),
            numbering: Numbering::Rows,
        }
    }
}

/// One marked part of a tray.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PartSlot {
    /// Part number, from 1, over the marked cells in numbering order.
    pub part: u32,
    /// Cell number, row by row from 1.
    pub cell: u32,
    /// Column, from 1.
    pub col: u32,
    /// Row, from 1 (top).
    pub row: u32,
    /// Offset of this part from the part as placed, mm.
    pub offset: Pt,
}

impl Tray {
    /// Reads `COLSxROWS@PITCH_X,PITCH_Y` (mm), e.g. `6x8@40,32`.
    pub fn parse(spec: &str) -> Result<Self, ProductionError> {
        let bad = || ProductionError::Syntax {
            what: "--array",
            text: spec.into(),
            form: "COLSxROWS@PITCH_X,PITCH_Y in mm, e.g. 6x8@40,32",
        };
        let (grid, pitch) = spec.trim().split_once('@').ok_or_else(bad)?;
        let (c, r) = grid.split_once(['x', 'X', '×']).ok_or_else(bad)?;
        let (px, py) = pitch.split_once(',').ok_or_else(bad)?;
        let cols: u32 = c.trim().parse().map_err(|_| bad())?;
        let rows: u32 = r.trim().parse().map_err(|_| bad())?;
        let px: f64 = px.trim().parse().map_err(|_| bad())?;
        let py: f64 = py.trim().parse().map_err(|_| bad())?;
        let tray = Tray {
            cols,
            rows,
            pitch_mm: [px, py],
            ..Tray::default()
        };
        tray.validate()?;
        Ok(tray)
    }

    /// Checks the counts, pitch and skipped cells.
    pub fn validate(&self) -> Result<(), ProductionError> {
        let cells = u64::from(self.cols) * u64::from(self.rows);
        if self.cols == 0 || self.rows == 0 || cells > u64::from(MAX_CELLS) {
            return Err(ProductionError::Tray(format!(
                "{} × {} cells: a tray has 1 to {MAX_CELLS} cells",
                self.cols, self.rows
            )));
        }
        let pitch_ok = |p: f64| p.is_finite() && (0.0..=crate::geom::MAX_COORD_MM).contains(&p);
        if !self.pitch_mm.iter().all(|&p| pitch_ok(p)) {
            return Err(ProductionError::Tray(format!(
                "pitch {} × {} mm: a pitch is a length from 0 to {} mm",
                self.pitch_mm[0],
                self.pitch_mm[1],
                crate::geom::MAX_COORD_MM
            )));
        }
        if let Some(&c) = self.skip.iter().find(|&&c| c == 0 || c > self.cells()) {
            return Err(ProductionError::Tray(format!(
                "cell {c} to skip is not on the tray (cells 1 to {}, row by row)",
                self.cells()
            )));
        }
        if self.parts().is_empty() {
            return Err(ProductionError::Tray(
                "every cell is skipped: nothing to mark".into(),
            ));
        }
        Ok(())
    }

    /// The number of cells.
    pub fn cells(&self) -> u32 {
        self.cols.saturating_mul(self.rows)
    }

    fn skip_set(&self) -> std::collections::BTreeSet<u32> {
        self.skip.iter().copied().collect()
    }

    /// The marked parts in numbering order.
    pub fn parts(&self) -> Vec<PartSlot> {
        let skip = self.skip_set();
        let mut out = Vec::new();
        for r in 0..self.rows {
            let reverse = self.numbering == Numbering::Serpentine && r % 2 == 1;
            for k in 0..self.cols {
                let c = if reverse { self.cols - 1 - k } else { k };
                let cell = r * self.cols + c + 1;
                if skip.contains(&cell) {
                    continue;
                }
                out.push(PartSlot {
                    part: out.len() as u32 + 1,
                    cell,
                    col: c + 1,
                    row: r + 1,
                    offset: Pt::new(
                        f64::from(c) * self.pitch_mm[0],
                        f64::from(r) * self.pitch_mm[1],
                    ),
                });
            }
        }
        out
    }

    /// The offset of cell `cell` (row by row from 1), mm.
    pub fn cell_offset(&self, cell: u32) -> Option<Pt> {
        let i = cell.checked_sub(1)?;
        (cell <= self.cells()).then(|| {
            Pt::new(
                f64::from(i % self.cols) * self.pitch_mm[0],
                f64::from(i / self.cols) * self.pitch_mm[1],
            )
        })
    }
}

/// Reads `--skip 3,17`: cell numbers, row by row from 1.
pub fn parse_skip(text: &str) -> Result<Vec<u32>, ProductionError> {
    text.split(',')
        .map(|c| {
            c.trim()
                .parse::<u32>()
                .ok()
                .filter(|&n| n > 0)
                .ok_or(ProductionError::Syntax {
                    what: "--skip",
                    text: text.into(),
                    form: "cell numbers from 1, row by row, separated by commas, e.g. 3,17",
                })
        })
        .collect()
}

/// Serial numbers: part `k` (from 1) gets `start + step·(k − 1)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Serial {
    /// The first part's serial.
    pub start: i64,
    /// From one part to the next.
    pub step: i64,
}

impl Default for Serial {
    fn default() -> Self {
        Self { start: 1, step: 1 }
    }
}

impl Serial {
    /// Reads `START[:STEP]`.
    pub fn parse(text: &str) -> Result<Self, ProductionError> {
        let bad = || ProductionError::Syntax {
            what: "--serial",
            text: text.into(),
            form: "START or START:STEP, whole numbers, e.g. 1001 or 1001:2",
        };
        let (a, b) = match text.trim().split_once(':') {
            Some((a, b)) => (a, Some(b)),
            None => (text.trim(), None),
        };
        let start: i64 = a.trim().parse().map_err(|_| bad())?;
        let step: i64 = b.map_or(Ok(1), |b| b.trim().parse().map_err(|_| bad()))?;
        Ok(Serial { start, step })
    }

    /// The serial of part `part` (from 1); `None` when it overflows.
    pub fn of(&self, part: u32) -> Option<i64> {
        self.step
            .checked_mul(i64::from(part.checked_sub(1)?))?
            .checked_add(self.start)
    }

    /// The serial after `parts` parts: where the next tray starts.
    pub fn after(&self, parts: u32) -> Option<i64> {
        self.step
            .checked_mul(i64::from(parts))?
            .checked_add(self.start)
    }
}

/// The date and time the fields `{date}` and `{time}` show (minutes; no time zone).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Stamp(pub chrono::NaiveDateTime);

impl Stamp {
    /// Now, in local time.
    pub fn now() -> Self {
        Stamp(chrono::Local::now().naive_local())
    }

    /// Reads `YYYY-MM-DD` or `YYYY-MM-DDTHH:MM`.
    pub fn parse(text: &str) -> Result<Self, ProductionError> {
        let t = text.trim();
        chrono::NaiveDateTime::parse_from_str(t, "%Y-%m-%dT%H:%M")
            .or_else(|_| {
                chrono::NaiveDate::parse_from_str(t, "%Y-%m-%d")
                    .map(|d| d.and_time(chrono::NaiveTime::MIN))
            })
            .map(Stamp)
            .map_err(|_| ProductionError::Syntax {
                what: "--date",
                text: text.into(),
                form: "YYYY-MM-DD or YYYY-MM-DDTHH:MM, e.g. 2026-12-07T14:30",
            })
    }
}

impl fmt::Display for Stamp {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.0.format("%Y-%m-%dT%H:%M"))
    }
}

/// Data per part from a CSV file: a header row, then row k for part k.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct DataTable {
    /// The file it was read from.
    pub file: String,
    /// Column names.
    pub header: Vec<String>,
    /// Rows (each as long as the header).
    pub rows: Vec<Vec<String>>,
}

/// Largest data file read, bytes (a CSV of a million parts is far below it).
pub const MAX_DATA_BYTES: u64 = 64 << 20;
/// Longest value of one data cell, characters: text marked on a part, not a document.
pub const MAX_CELL_CHARS: usize = 1_000;

impl DataTable {
    /// Reads a CSV file: a header row, then one row per part. A row of another length than the
    /// header, a value over [`MAX_CELL_CHARS`] characters, or a file over [`MAX_DATA_BYTES`] is
    /// an error naming the file and the line.
    pub fn read(path: &std::path::Path) -> Result<Self, ProductionError> {
        let file = path.display().to_string();
        let bad = |what: String| ProductionError::Data(format!("{file}: {what}"));
        let size = std::fs::metadata(path)
            .map_err(|e| bad(format!("cannot read: {e}")))?
            .len();
        if size > MAX_DATA_BYTES {
            return Err(bad(format!(
                "{size} bytes, beyond the {MAX_DATA_BYTES} a data file may have"
            )));
        }
        let bytes = std::fs::read(path).map_err(|e| bad(format!("cannot read: {e}")))?;
        Self::parse(&bytes, &file)
    }

    /// [`DataTable::read`] on the file's bytes; `file` names it in errors.
    pub fn parse(bytes: &[u8], file: &str) -> Result<Self, ProductionError> {
        let bad = |what: String| ProductionError::Data(format!("{file}: {what}"));
        let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
        let mut reader = csv::ReaderBuilder::new()
            .has_headers(true)
            .flexible(false)
            .trim(csv::Trim::All)
            .from_reader(bytes);
        let header: Vec<String> = reader
            .headers()
            .map_err(|e| bad(format!("no header row ({e})")))?
            .iter()
            .map(str::to_string)
            .collect();
        if header.iter().all(String::is_empty) {
            return Err(bad("no header row (the first row names the columns)".into()));
        }
        let mut rows = Vec::new();
        for record in reader.records() {
            let record = record.map_err(|e| {
                let line = e.position().map(|p| p.line()).unwrap_or(0);
                bad(format!("line {line}: {}", csv_error_words(&e)))
            })?;
            let line = record.position().map(|p| p.line()).unwrap_or(0);
            if let Some(v) = record.iter().find(|v| v.chars().count() > MAX_CELL_CHARS) {
                return Err(bad(format!(
                    "line {line}: a value of {} characters (at most {MAX_CELL_CHARS})",
                    v.chars().count()
                )));
            }
            if record.iter().any(|v| v.contains(['\n', '\r'])) {
                return Err(bad(format!("line {line}: a value spans several lines")));
            }
            rows.push(record.iter().map(str::to_string).collect());
        }
        Ok(Self {
            file: file.to_string(),
            header,
            rows,
        })
    }

    /// `Ok` when the table has `column`; else the error listing the columns it has.
    pub fn check_column(&self, column: &str) -> Result<(), TemplateError> {
        if self.header.iter().any(|h| h == column) {
            Ok(())
        } else {
            Err(TemplateError::MissingColumn {
                file: self.file.clone(),
                column: column.to_string(),
                columns: self.header.clone(),
            })
        }
    }

    /// The value of `column` for part `part` (from 1).
    pub fn value(&self, column: &str, part: u32) -> Option<&str> {
        let c = self.header.iter().position(|h| h == column)?;
        let row = self.rows.get(usize::try_from(part).ok()?.checked_sub(1)?)?;
        row.get(c).map(String::as_str)
    }
}

/// A CSV reader's error in words, without the line (the caller says it).
fn csv_error_words(e: &csv::Error) -> String {
    match e.kind() {
        csv::ErrorKind::UnequalLengths {
            expected_len, len, ..
        } => format!("{len} values, but the header has {expected_len} columns"),
        csv::ErrorKind::Utf8 { .. } => "not UTF-8 text".into(),
        _ => e.to_string(),
    }
}

/// A piece of a template text.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Piece {
    /// Text as written (braces unescaped).
    Text(String),
    /// A field.
    Field(Field),
}

/// A field of a template text.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Field {
    /// The part's serial number, zero-padded to the width when one is given.
    Serial(Option<usize>),
    /// The part number (from 1).
    Part,
    /// The part's row (from 1, top).
    Row,
    /// The part's column (from 1, left).
    Col,
    /// The date, in strftime form.
    Date(String),
    /// The time, in strftime form.
    Time(String),
    /// A column of the part's CSV row.
    Csv(String),
}

/// Splits a template text into pieces; the error says what is wrong (the caller names the text
/// and where it is).
pub fn parse_template(text: &str) -> Result<Vec<Piece>, TemplateError> {
    let mut pieces = Vec::new();
    let mut lit = String::new();
    let mut chars = text.char_indices().peekable();
    while let Some((i, c)) = chars.next() {
        match c {
            '{' if chars.peek().map(|p| p.1) == Some('{') => {
                chars.next();
                lit.push('{');
            }
            '}' if chars.peek().map(|p| p.1) == Some('}') => {
                chars.next();
                lit.push('}');
            }
            '}' => return Err(TemplateError::UnbalancedClose { at: i + 1 }),
            '{' => {
                let rest = &text[i + 1..];
                let end = rest
                    .find(['}', '{'])
                    .filter(|&e| rest[e..].starts_with('}'))
                    .ok_or(TemplateError::UnbalancedOpen { at: i + 1 })?;
                let body = &rest[..end];
                if !lit.is_empty() {
                    pieces.push(Piece::Text(std::mem::take(&mut lit)));
                }
                pieces.push(Piece::Field(field(body)?));
                for _ in 0..body.chars().count() + 1 {
                    chars.next();
                }
            }
            c => lit.push(c),
        }
    }
    if !lit.is_empty() {
        pieces.push(Piece::Text(lit));
    }
    Ok(pieces)
}

/// True when the text holds a brace: a template (fields, or escaped braces).
pub fn is_template(text: &str) -> bool {
    text.contains(['{', '}'])
}

fn field(body: &str) -> Result<Field, TemplateError> {
    let (name, arg) = match body.split_once(':') {
        Some((n, a)) => (n.trim(), Some(a)),
        None => (body.trim(), None),
    };
    let f = match (name, arg) {
        ("serial", None) => Field::Serial(None),
        ("serial", Some(w)) => {
            let width: usize = w
                .trim()
                .parse()
                .ok()
                .filter(|&n| n <= MAX_SERIAL_WIDTH)
                .ok_or_else(|| TemplateError::SerialWidth { body: body.into() })?;
            Field::Serial(Some(width))
        }
        ("part", None) => Field::Part,
        ("row", None) => Field::Row,
        ("col", None) => Field::Col,
        ("date", f) => Field::Date(strftime(f.unwrap_or("%Y-%m-%d"), body)?),
        ("time", f) => Field::Time(strftime(f.unwrap_or("%H:%M"), body)?),
        ("csv", Some(c)) if !c.trim().is_empty() => Field::Csv(c.trim().to_string()),
        ("csv", _) => return Err(TemplateError::NoColumnName { body: body.into() }),
        _ => return Err(TemplateError::UnknownField { body: body.into() }),
    };
    Ok(f)
}

/// A strftime format checked in full (chrono panics at display time on a bad one).
fn strftime(format: &str, body: &str) -> Result<String, TemplateError> {
    use chrono::format::{Item, StrftimeItems};
    if StrftimeItems::new(format).any(|i| matches!(i, Item::Error)) {
        return Err(TemplateError::BadFormat {
            body: body.into(),
            format: format.into(),
        });
    }
    Ok(format.to_string())
}

/// What the fields of one part show.
#[derive(Debug, Clone, Copy)]
pub struct PartValues<'a> {
    /// The part's place on the tray.
    pub slot: PartSlot,
    /// Its serial number.
    pub serial: i64,
    /// The date and time.
    pub stamp: Stamp,
    /// The CSV data, when given.
    pub data: Option<&'a DataTable>,
}

/// The text of `pieces` for one part; `Err` names what is missing (a CSV column or row).
pub fn render(pieces: &[Piece], v: &PartValues) -> Result<String, TemplateError> {
    let mut out = String::new();
    for p in pieces {
        match p {
            Piece::Text(t) => out.push_str(t),
            Piece::Field(f) => match f {
                Field::Serial(None) => out.push_str(&v.serial.to_string()),
                Field::Serial(Some(w)) => out.push_str(&format!("{:0w$}", v.serial, w = *w)),
                Field::Part => out.push_str(&v.slot.part.to_string()),
                Field::Row => out.push_str(&v.slot.row.to_string()),
                Field::Col => out.push_str(&v.slot.col.to_string()),
                Field::Date(f) | Field::Time(f) => out.push_str(&v.stamp.0.format(f).to_string()),
                Field::Csv(c) => {
                    let data = v
                        .data
                        .ok_or_else(|| TemplateError::NoData { column: c.clone() })?;
                    data.check_column(c)?;
                    let value =
                        data.value(c, v.slot.part)
                            .ok_or_else(|| TemplateError::MissingRow {
                                file: data.file.clone(),
                                rows: data.rows.len(),
                                part: v.slot.part,
                            })?;
                    out.push_str(value);
                }
            },
        }
    }
    Ok(out)
}

/// Why a template text cannot be read or rendered for a part. The messages say what is wrong
/// with the field; the caller names the text and where it is.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum TemplateError {
    /// A `}` that closes no field (write `}}` for a brace).
    #[error("an unbalanced '}}' at character {at}")]
    UnbalancedClose {
        /// Where it is in the text, from 1.
        at: usize,
    },
    /// A `{` whose field is never closed (write `{{` for a brace).
    #[error("an unbalanced '{{' at character {at}")]
    UnbalancedOpen {
        /// Where it is in the text, from 1.
        at: usize,
    },
    /// A field that is none of the known ones.
    #[error(
        "unknown field {{{body}}} (fields: serial, serial:05, part, row, col, date, time, \
         csv:COLUMN)"
    )]
    UnknownField {
        /// The field as written between its braces.
        body: String,
    },
    /// A serial's width that is not a number up to [`MAX_SERIAL_WIDTH`].
    #[error(
        "{{{body}}}: a serial's width is a number up to {MAX_SERIAL_WIDTH}, e.g. {{serial:05}}"
    )]
    SerialWidth {
        /// The field as written between its braces.
        body: String,
    },
    /// A date or time field whose format is not strftime.
    #[error("{{{body}}}: '{format}' is not a strftime format (e.g. %Y-%m-%d)")]
    BadFormat {
        /// The field as written between its braces.
        body: String,
        /// The format it gives.
        format: String,
    },
    /// A `{csv:}` field without a column name.
    #[error("{{{body}}}: name the column, e.g. {{csv:lot}}")]
    NoColumnName {
        /// The field as written between its braces.
        body: String,
    },
    /// A `{csv:COLUMN}` field with no data file given.
    #[error("{{csv:{column}}} needs a data file (--data FILE.csv)")]
    NoData {
        /// The column the field names.
        column: String,
    },
    /// A `{csv:COLUMN}` field naming a column the data file does not have.
    #[error("{file}: no column '{column}' (columns: {})", columns.join(", "))]
    MissingColumn {
        /// The data file.
        file: String,
        /// The column the field names.
        column: String,
        /// The columns the file has.
        columns: Vec<String>,
    },
    /// A part beyond the data file's rows.
    #[error("{file}: {rows} data rows, but part {part} needs row {part}")]
    MissingRow {
        /// The data file.
        file: String,
        /// The rows it has.
        rows: usize,
        /// The part (its row number).
        part: u32,
    },
}

/// How a template's lines sit on its anchor, along the baseline.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum TextAlign {
    /// Lines start at the anchor.
    #[default]
    Start,
    /// Lines are centred on it.
    Middle,
    /// Lines end at it.
    End,
}

/// A text of the artwork holding fields: kept as written, shaped per part.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TextTemplate {
    /// The text with its fields; lines separated by `\n`.
    pub text: String,
    /// The element it came from, as errors name it (`<text id="sn">`, `MTEXT (handle 2A)`).
    pub element: String,
    /// Its line in the file, where known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub line: Option<u32>,
    /// The layer its glyphs go on.
    pub layer: String,
    /// Font family list, as CSS writes it.
    pub family: String,
    /// Font size (em) in frame units.
    pub em: f64,
    /// Baseline-to-baseline distance in frame units.
    pub pitch: f64,
    /// Alignment along the baseline.
    pub align: TextAlign,
    /// Offset of the first baseline above the anchor, in frame units (y up).
    pub first_baseline: f64,
    /// The text frame (x along the baseline, y up, origin at the anchor) to machine mm:
    /// `[a, b, c, d, e, f]` with `x' = a·x + c·y + e`, `y' = b·x + d·y + f`.
    pub frame: [f64; 6],
}

impl TextTemplate {
    /// Moves the template by `d` mm (placement, tray offsets).
    pub fn moved(&self, d: Pt) -> Self {
        let mut t = self.clone();
        t.frame[4] += d.x;
        t.frame[5] += d.y;
        t
    }
}

/// A production job: the part, its templates, and how it is repeated and numbered.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Production {
    /// The part's own outlines (every layer), as imported and placed.
    pub part: Vec<crate::document::Geometry>,
    /// The part's texts with fields.
    #[serde(default)]
    pub templates: Vec<TextTemplate>,
    /// How the part is repeated.
    #[serde(default)]
    pub tray: Tray,
    /// Serial numbers.
    #[serde(default)]
    pub serial: Serial,
    /// The date and time the fields show (none: the moment the tray is made).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stamp: Option<Stamp>,
    /// Data per part.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub data: Option<DataTable>,
    /// The highest serial written to a parts log: never handed out again.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub logged_through: Option<i64>,
    /// The chord tolerance the texts are shaped with (the artwork's import tolerance), mm.
    #[serde(default = "default_chord_tol")]
    pub chord_tol_mm: f64,
    /// The part's codes (DataMatrix, QR, Code 128), each with its content per part.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub codes: Vec<super::CodeSpec>,
}

fn default_chord_tol() -> f64 {
    0.01
}

impl Default for Production {
    fn default() -> Self {
        Self {
            part: Vec::new(),
            templates: Vec::new(),
            tray: Tray::default(),
            serial: Serial::default(),
            stamp: None,
            data: None,
            logged_through: None,
            chord_tol_mm: default_chord_tol(),
            codes: Vec::new(),
        }
    }
}

impl Production {
    /// A production of one part: its outlines (in the file's coordinates) and texts with
    /// fields, marked once (a 1 × 1 tray, serials from 1) until a tray is set.
    pub fn of_part(
        part: Vec<crate::document::Geometry>,
        templates: Vec<TextTemplate>,
        chord_tol_mm: f64,
    ) -> Self {
        Self {
            part,
            templates,
            chord_tol_mm,
            ..Self::default()
        }
    }
}

/// Production options given from outside a document (the command line's `--array`, `--skip`,
/// `--numbering`, `--serial`, `--date`, `--data`), each set on the production when given.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TraySettings {
    /// The tray.
    pub tray: Option<Tray>,
    /// Cells left out (replaces the tray's).
    pub skip: Option<Vec<u32>>,
    /// Numbering (replaces the tray's).
    pub numbering: Option<Numbering>,
    /// Serials.
    pub serial: Option<Serial>,
    /// The date and time fields show.
    pub stamp: Option<Stamp>,
    /// Data per part.
    pub data: Option<DataTable>,
    /// The part's codes (replace the production's).
    pub codes: Option<Vec<super::CodeSpec>>,
}

impl TraySettings {
    /// True when any option is given.
    pub fn is_set(&self) -> bool {
        *self != TraySettings::default()
    }

    /// Sets the given options on `p`; the tray is checked.
    pub fn apply(&self, p: &mut Production) -> Result<(), ProductionError> {
        if let Some(t) = &self.tray {
            p.tray = t.clone();
        }
        if let Some(skip) = &self.skip {
            p.tray.skip = skip.clone();
        }
        if let Some(n) = self.numbering {
            p.tray.numbering = n;
        }
        p.tray.validate()?;
        if let Some(s) = self.serial {
            p.serial = s;
        }
        if let Some(d) = self.stamp {
            p.stamp = Some(d);
        }
        if let Some(d) = &self.data {
            p.data = Some(d.clone());
        }
        if let Some(c) = &self.codes {
            p.codes = c.clone();
        }
        Ok(())
    }
}

/// The tray and serials of a production, as the GUI's Tray section edits them.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TraySetup {
    /// The tray.
    pub tray: Tray,
    /// Serials.
    pub serial: Serial,
}

impl Production {
    /// Its tray and serials.
    pub fn setup(&self) -> TraySetup {
        TraySetup {
            tray: self.tray.clone(),
            serial: self.serial,
        }
    }
}

/// What one marked part carries: for the report and the parts log.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PartRecord {
    /// Part number (from 1).
    pub part: u32,
    /// Cell number (row by row from 1).
    pub cell: u32,
    /// Column and row (from 1).
    pub col: u32,
    /// Row (from 1, top).
    pub row: u32,
    /// Offset from the part as placed, mm.
    pub position_mm: [f64; 2],
    /// Serial number.
    pub serial: i64,
    /// Every template's text as marked, in template order.
    pub texts: Vec<String>,
    /// Every code's content as marked, in code order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub codes: Vec<String>,
}

/// A production input that cannot be used; every message names what and where.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ProductionError {
    /// A command-line value that does not read.
    #[error("{what} '{text}': expected {form}")]
    Syntax {
        /// The option.
        what: &'static str,
        /// What was given.
        text: String,
        /// The expected form.
        form: &'static str,
    },
    /// The tray cannot be made.
    #[error("tray: {0}")]
    Tray(String),
    /// A template text is wrong, or a field has no value.
    #[error("{element}{} text \"{text}\": {why}", line.map(|l| format!(" (line {l})")).unwrap_or_default())]
    Template {
        /// The text's element.
        element: String,
        /// Its line.
        line: Option<u32>,
        /// The text.
        text: String,
        /// What is wrong.
        why: String,
    },
    /// The data file cannot be used.
    #[error("{0}")]
    Data(String),
    /// A code cannot be read or made (`--code TEXT`, or its content for a part).
    #[error("code '{text}': {why}")]
    Code {
        /// The code as given.
        text: String,
        /// What is wrong.
        why: String,
    },
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tray_specs_read_and_bad_ones_say_the_form() {
        let t = Tray::parse("6x8@40,32").unwrap();
        assert_eq!((t.cols, t.rows, t.pitch_mm), (6, 8, [40.0, 32.0]));
        for bad in [
            "6x8",
            "6x@4,4",
            "0x3@1,1",
            "6x8@40",
            "6x8@-1,2",
            "200x200@1,1",
        ] {
            let e = Tray::parse(bad).unwrap_err().to_string();
            assert!(!e.contains('\n'), "{e}");
            assert!(
                e.contains(bad) || e.contains("cells") || e.contains("pitch"),
                "{e}"
            );
        }
        assert_eq!(parse_skip("3, 17").unwrap(), [3, 17]);
        assert!(parse_skip("3,x").is_err() && parse_skip("0").is_err());
    }

    #[test]
    fn numbering_by_rows_and_serpentine_skips_cells() {
        let mut t = Tray::parse("3x2@10,20").unwrap();
        t.skip = vec![2];
        let rows: Vec<(u32, u32)> = t.parts().iter().map(|p| (p.part, p.cell)).collect();
        assert_eq!(rows, [(1, 1), (2, 3), (3, 4), (4, 5), (5, 6)]);
        t.numbering = Numbering::Serpentine;
        let s: Vec<u32> = t.parts().iter().map(|p| p.cell).collect();
        assert_eq!(s, [1, 3, 6, 5, 4]);
        let p = t.parts()[2];
        assert_eq!((p.col, p.row, p.offset), (3, 2, Pt::new(20.0, 20.0)));
        t.skip = vec![7];
        assert!(t.validate().is_err());
        t.skip = (1..=6).collect();
        assert!(t.validate().is_err());
    }

    #[test]
    fn serials_step_and_overflow() {
        let s = Serial::parse("1001").unwrap();
        assert_eq!(
            (s.of(1), s.of(48), s.after(48)),
            (Some(1001), Some(1048), Some(1049))
        );
        let s = Serial::parse("10:-2").unwrap();
        assert_eq!(s.of(3), Some(6));
        assert!(Serial::parse("a").is_err());
        assert_eq!(
            Serial {
                start: i64::MAX,
                step: 1
            }
            .of(2),
            None
        );
    }

    fn values(data: Option<&DataTable>) -> PartValues<'_> {
        PartValues {
            slot: PartSlot {
                part: 2,
                cell: 3,
                col: 3,
                row: 1,
                offset: Pt::new(0.0, 0.0),
            },
            serial: 1002,
            stamp: Stamp::parse("2026-12-07T14:30").unwrap(),
            data,
        }
    }

    #[test]
    fn templates_render_every_field() {
        let data = DataTable {
            file: "lots.csv".into(),
            header: vec!["lot".into(), "op".into()],
            rows: vec![vec!["A1".into(), "x".into()], vec!["B2".into(), "y".into()]],
        };
        let p = parse_template(
            "SN {serial:05} {serial} p{part} r{row}c{col} {date} {time} {date:%d.%m.%y} {csv:lot} {{x}}",
        )
        .unwrap();
        assert_eq!(
            render(&p, &values(Some(&data))).unwrap(),
            "SN 01002 1002 p2 r1c3 2026-12-07 14:30 07.12.26 B2 {x}"
        );
    }

    #[test]
    fn bad_templates_say_what_is_wrong() {
        for (t, says) in [
            (
                "SN {seriall}",
                "unknown field {seriall} (fields: serial, serial:05, part, row, col, date, time, \
                 csv:COLUMN)",
            ),
            ("SN {serial", "unbalanced '{'"),
            ("SN serial}", "unbalanced '}'"),
            ("{date:%Q}", "not a strftime format"),
            ("{csv:}", "name the column"),
            ("{serial:abc}", "width"),
            ("a {b {c}", "unbalanced '{'"),
        ] {
            let e = parse_template(t).unwrap_err().to_string();
            assert!(e.contains(says), "{t}: {e}");
        }
        let data = DataTable {
            file: "lots.csv".into(),
            header: vec!["lot".into()],
            rows: vec![vec!["A1".into()]],
        };
        let p = parse_template("{csv:op}").unwrap();
        assert_eq!(
            render(&p, &values(Some(&data))).unwrap_err().to_string(),
            "lots.csv: no column 'op' (columns: lot)"
        );
        let p = parse_template("{csv:lot}").unwrap();
        let e = render(&p, &values(Some(&data))).unwrap_err().to_string();
        assert!(e.contains("1 data rows, but part 2"), "{e}");
        assert_eq!(
            render(&p, &values(None)).unwrap_err().to_string(),
            "{csv:lot} needs a data file (--data FILE.csv)"
        );
    }

    #[test]
    fn dates_read_with_or_without_time() {
        assert_eq!(
            Stamp::parse("2026-12-07").unwrap().to_string(),
            "2026-12-07T00:00"
        );
        assert!(Stamp::parse("2026-13-07").is_err());
        assert!(Stamp::parse("07.12.2026").is_err());
    }
}
