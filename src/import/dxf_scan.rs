//! A plain reader of DXF group-code pairs (ASCII and binary), for what the `dxf` crate does not
//! keep: the layer table's frozen flag (it reads the colour, hence "off", but drops flag 70), and
//! entity types it skips without a word (HATCH, MESH, …), with the block that holds them.

use std::borrow::Cow;

/// The binary DXF sentinel.
const BINARY_SENTINEL: &[u8] = b"AutoCAD Binary DXF\r\n\x1a\0";

/// One group-code pair: the code, its value as text, and where it is (the ASCII line of the
/// value; `None` in binary files).
#[derive(Debug, Clone, PartialEq)]
pub struct Pair<'b> {
    /// Group code.
    pub code: i32,
    /// The value as text (numbers of binary files formatted).
    pub value: Cow<'b, str>,
    /// 1-based line of the value in an ASCII file.
    pub line: Option<u32>,
}

/// The pairs of an ASCII DXF text, until the end or the first line that is not a group code.
fn ascii_pairs(text: &str) -> impl Iterator<Item = Pair<'_>> {
    let mut lines = text.lines().map(str::trim).enumerate();
    std::iter::from_fn(move || {
        let (_, code) = lines.next()?;
        let (i, value) = lines.next()?;
        Some(Pair {
            code: code.parse().ok()?,
            value: Cow::Borrowed(value),
            line: u32::try_from(i + 1).ok(),
        })
    })
}

/// Value types of binary DXF by group code (the DXF reference's ranges).
enum Kind {
    Str,
    F64,
    I16,
    I32,
    I64,
    Bool,
    Bytes,
}

fn kind(code: i32) -> Option<Kind> {
    Some(match code {
        0..=9
        | 100..=102
        | 105
        | 300..=309
        | 320..=369
        | 390..=399
        | 410..=419
        | 430..=439
        | 470..=481
        | 999
        | 1000..=1003
        | 1005..=1009 => Kind::Str,
        10..=59 | 110..=149 | 210..=239 | 460..=469 | 1010..=1059 => Kind::F64,
        60..=79 | 170..=179 | 270..=289 | 370..=389 | 400..=409 | 1060..=1070 => Kind::I16,
        90..=99 | 420..=429 | 440..=459 | 1071 => Kind::I32,
        160..=169 => Kind::I64,
        290..=299 => Kind::Bool,
        310..=319 | 1004 => Kind::Bytes,
        _ => return None,
    })
}

/// The pairs of a binary DXF after its sentinel, until the end or the first pair that cannot be
/// read.
fn binary_pairs(b: &[u8]) -> impl Iterator<Item = Pair<'_>> {
    // R13 and later write 2-byte codes: the first pair (0, "SECTION") then starts 00 00
    let two_byte_codes = b.get(1) == Some(&0);
    let mut i = 0;
    std::iter::from_fn(move || {
        let mut take = |n: usize| -> Option<&[u8]> {
            let s = b.get(i..i + n)?;
            i += n;
            Some(s)
        };
        let code = if two_byte_codes {
            let c = take(2)?;
            i32::from(i16::from_le_bytes([c[0], c[1]]))
        } else {
            match take(1)? {
                [255] => {
                    let c = take(2)?;
                    i32::from(i16::from_le_bytes([c[0], c[1]]))
                }
                c => i32::from(c[0]),
            }
        };
        let num = |s: &[u8]| -> [u8; 8] {
            let mut a = [0; 8];
            a[..s.len()].copy_from_slice(s);
            a
        };
        let value: Cow<'_, str> = match kind(code)? {
            Kind::Str => {
                let len = b.get(i..)?.iter().position(|&c| c == 0)?;
                let s = String::from_utf8_lossy(&b[i..i + len]);
                i += len + 1;
                s
            }
            Kind::F64 => f64::from_le_bytes(num(take(8)?)).to_string().into(),
            Kind::I16 => {
                let v = take(2)?;
                i16::from_le_bytes([v[0], v[1]]).to_string().into()
            }
            Kind::I32 => {
                let v = num(take(4)?);
                i32::from_le_bytes([v[0], v[1], v[2], v[3]])
                    .to_string()
                    .into()
            }
            Kind::I64 => i64::from_le_bytes(num(take(8)?)).to_string().into(),
            Kind::Bool => {
                let v = take(if two_byte_codes { 1 } else { 2 })?;
                i32::from(v.iter().any(|&x| x != 0)).to_string().into()
            }
            Kind::Bytes => {
                let len = usize::from(take(1)?[0]);
                take(len)?;
                Cow::Borrowed("")
            }
        };
        Some(Pair {
            code,
            value,
            line: None,
        })
    })
}

/// How the layer table shows one layer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct LayerState {
    /// Off: a negative colour number.
    pub off: bool,
    /// Frozen: bit 1 of flag 70.
    pub frozen: bool,
}

/// An entity found by the scan.
#[derive(Debug, Clone, PartialEq)]
pub struct ScannedEntity {
    /// Its type (`HATCH`).
    pub kind: String,
    /// Its handle, `?` when it has none.
    pub handle: String,
    /// Its layer, `?` when it names none.
    pub layer: String,
    /// The block whose definition holds it (`None` in the ENTITIES section).
    pub block: Option<String>,
    /// Flagged invisible (group 60 = 1).
    pub invisible: bool,
    /// The line of its type name (ASCII files).
    pub line: Option<u32>,
}

/// What the scan found.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Scan {
    /// The layers of the LAYER table with their state, by name as written.
    pub layers: Vec<(String, LayerState)>,
    /// The entities of the ENTITIES and BLOCKS sections whose type the caller asked for.
    pub entities: Vec<ScannedEntity>,
    /// Each MTEXT's text as written (codes 3 then 1), by handle in upper-case hex: the `dxf`
    /// crate drops an escape such as `\}` within the last six characters of a value (its
    /// `\U+XXXX` reader waits for six more), which loses the closing brace of a field.
    pub mtext: Vec<(String, String)>,
}

/// One record (the pairs from a code 0 to the next).
#[derive(Default)]
struct Record {
    kind: String,
    line: Option<u32>,
    name: Option<String>,
    handle: Option<String>,
    layer: Option<String>,
    colour: i32,
    flags: i32,
    invisible: bool,
    /// Text values (codes 3 and 1), in order.
    text: String,
    /// The code 1 value (the last piece of an MTEXT's text).
    last_text: Option<String>,
}

/// Scans a DXF file, ASCII or binary, in one pass: the layer table's layers with their state,
/// and the entities whose type `keep` accepts with the block holding them. Reading stops
/// quietly at anything it cannot read (the `dxf` crate reports malformed files).
pub fn scan(bytes: &[u8], keep: impl Fn(&str) -> bool) -> Scan {
    match bytes.strip_prefix(BINARY_SENTINEL) {
        Some(rest) => scan_pairs(binary_pairs(rest), keep),
        None => {
            let text = String::from_utf8_lossy(bytes);
            scan_pairs(ascii_pairs(&text), keep)
        }
    }
}

fn scan_pairs<'a>(pairs: impl Iterator<Item = Pair<'a>>, keep: impl Fn(&str) -> bool) -> Scan {
    let mut out = Scan::default();
    let mut section = String::new();
    let mut in_layer_table = false;
    let mut block: Option<String> = None;
    // the next code 2 names a section / a table
    let (mut naming_section, mut naming_table) = (false, false);
    let mut record: Option<Record> = None;
    let mut finish = |r: Record,
                      section: &str,
                      in_layer_table: bool,
                      block: &mut Option<String>| {
        match section {
            "TABLES" if in_layer_table && r.kind == "LAYER" => {
                if let Some(name) = r.name.filter(|n| !n.is_empty()) {
                    let state = LayerState {
                        off: r.colour < 0,
                        frozen: r.flags & 1 != 0,
                    };
                    out.layers.push((name, state));
                }
            }
            "ENTITIES" | "BLOCKS" => match r.kind.as_str() {
                "BLOCK" => *block = r.name,
                "ENDBLK" => *block = None,
                "MTEXT" => {
                    if let Some(h) = r.handle {
                        let mut text = r.text;
                        text.push_str(r.last_text.as_deref().unwrap_or(""));
                        out.mtext.push((h.to_ascii_uppercase(), text));
                    }
                }
                kind if keep(kind) => out.entities.push(ScannedEntity {
                    kind: r.kind.clone(),
                    handle: r.handle.unwrap_or_else(|| "?".into()),
                    layer: r.layer.unwrap_or_else(|| "?".into()),
                    block: block.clone(),
                    invisible: r.invisible,
                    line: r.line,
                }),
                _ => {}
            },
            _ => {}
        }
    };
    for p in pairs {
        if p.code == 0 {
            if let Some(r) = record.take() {
                finish(r, &section, in_layer_table, &mut block);
            }
            match p.value.as_ref() {
                "SECTION" => naming_section = true,
                "ENDSEC" => {
                    section.clear();
                    block = None;
                }
                "TABLE" => naming_table = true,
                "ENDTAB" => in_layer_table = false,
                kind => {
                    record = Some(Record {
                        kind: kind.to_string(),
                        line: p.line,
                        ..Record::default()
                    })
                }
            }
            continue;
        }
        if p.code == 2 && naming_section {
            section = p.value.to_string();
            naming_section = false;
            continue;
        }
        if p.code == 2 && naming_table {
            in_layer_table = p.value == "LAYER";
            naming_table = false;
            continue;
        }
        let Some(r) = record.as_mut() else {
            continue;
        };
        let int = || p.value.trim().parse::<i32>().unwrap_or(0);
        match p.code {
            2 => r.name = Some(p.value.to_string()),
            5 => r.handle = Some(p.value.to_string()),
            8 => r.layer = Some(p.value.to_string()),
            60 => r.invisible = int() != 0,
            62 => r.colour = int(),
            70 => r.flags = int(),
            3 if r.kind == "MTEXT" => r.text.push_str(&p.value),
            1 if r.kind == "MTEXT" => r.last_text = Some(p.value.to_string()),
            _ => {}
        }
    }
    if let Some(r) = record.take() {
        finish(r, &section, in_layer_table, &mut block);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const ASCII: &str = "0\nSECTION\n2\nTABLES\n0\nTABLE\n2\nLAYER\n70\n3\n\
        0\nLAYER\n2\nA\n70\n0\n62\n7\n\
        0\nLAYER\n2\nOFF\n70\n0\n62\n-1\n\
        0\nLAYER\n2\nFROZEN\n70\n1\n62\n3\n\
        0\nLAYER\n2\nBOTH\n70\n5\n62\n-2\n\
        0\nENDTAB\n0\nTABLE\n2\nSTYLE\n0\nSTYLE\n2\nNOT-A-LAYER\n70\n1\n0\nENDTAB\n0\nENDSEC\n\
        0\nSECTION\n2\nBLOCKS\n0\nBLOCK\n8\n0\n2\nB1\n70\n0\n0\nHATCH\n5\n2A\n8\nX\n0\nENDBLK\n0\nENDSEC\n\
        0\nSECTION\n2\nENTITIES\n0\nHATCH\n5\n2B\n8\nY\n60\n1\n0\nLINE\n8\nZ\n0\nENDSEC\n0\nEOF\n";

    fn state(off: bool, frozen: bool) -> LayerState {
        LayerState { off, frozen }
    }

    #[test]
    fn ascii_layer_states_and_scanned_entities() {
        let s = scan(ASCII.as_bytes(), |k| k == "HATCH");
        assert_eq!(
            s.layers,
            vec![
                ("A".to_string(), state(false, false)),
                ("OFF".to_string(), state(true, false)),
                ("FROZEN".to_string(), state(false, true)),
                ("BOTH".to_string(), state(true, true)),
            ]
        );
        let hatches = &s.entities;
        assert_eq!(hatches.len(), 2);
        assert_eq!(hatches[0].block.as_deref(), Some("B1"));
        assert_eq!(
            (hatches[0].handle.as_str(), hatches[0].layer.as_str()),
            ("2A", "X")
        );
        assert!(!hatches[0].invisible);
        assert_eq!(hatches[1].block, None);
        assert!(hatches[1].invisible);
        // the line of the type name
        let line = ASCII.lines().position(|l| l == "2B").map(|i| i as u32 - 1);
        assert_eq!(hatches[1].line, line);
    }

    #[test]
    fn binary_pairs_read_like_ascii() {
        // R13+ binary: 2-byte codes, NUL-terminated strings, little-endian numbers
        let mut b = BINARY_SENTINEL.to_vec();
        let s = |b: &mut Vec<u8>, code: i16, v: &str| {
            b.extend(code.to_le_bytes());
            b.extend(v.as_bytes());
            b.push(0);
        };
        s(&mut b, 0, "SECTION");
        s(&mut b, 2, "TABLES");
        s(&mut b, 0, "TABLE");
        s(&mut b, 2, "LAYER");
        s(&mut b, 0, "LAYER");
        s(&mut b, 2, "F");
        b.extend(70i16.to_le_bytes());
        b.extend(1i16.to_le_bytes());
        b.extend(62i16.to_le_bytes());
        b.extend((-7i16).to_le_bytes());
        b.extend(10i16.to_le_bytes());
        b.extend(2.5f64.to_le_bytes());
        b.extend(290i16.to_le_bytes());
        b.push(1);
        s(&mut b, 0, "ENDTAB");
        s(&mut b, 0, "ENDSEC");
        s(&mut b, 0, "EOF");
        let p: Vec<Pair> = binary_pairs(&b[BINARY_SENTINEL.len()..]).collect();
        assert_eq!(p.len(), 13);
        assert_eq!((p[7].value.as_ref(), p[8].value.as_ref()), ("-7", "2.5"));
        assert_eq!(
            scan(&b, |_| false).layers,
            vec![("F".to_string(), state(true, true))]
        );
    }

    #[test]
    fn truncated_or_garbage_input_stops_quietly() {
        assert_eq!(ascii_pairs("0\nSECTION\nnot a code\nx\n").count(), 1);
        let mut b = BINARY_SENTINEL.to_vec();
        b.extend([0, 0, b'S']);
        assert_eq!(scan(&b, |_| true), Scan::default());
        assert_eq!(scan(&[0xff; 64], |_| true), Scan::default());
    }
}
