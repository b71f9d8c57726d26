//! A plain reader of DXF group-code pairs (ASCII and binary), for what the `dxf` crate does not
//! keep: the layer table's frozen flag (it reads the colour, hence "off", but drops flag 70), and
//! entity types it skips without a word (HATCH, MESH, …), with the block that holds them.

/// The binary DXF sentinel.
const BINARY_SENTINEL: &[u8] = b"AutoCAD Binary DXF\r\n\x1a\0";

/// One group-code pair: the code, its value as text, and where it is (the ASCII line of the
/// value; `None` in binary files).
#[derive(Debug, Clone, PartialEq)]
pub struct Pair<'b> {
    /// Group code.
    pub code: i32,
    /// The value as text (numbers of binary files formatted).
    pub value: std::borrow::Cow<'b, str>,
    /// 1-based line of the value in an ASCII file.
    pub line: Option<u32>,
}

/// The pairs of a DXF file, ASCII or binary, until the end or the first pair that cannot be
/// read (the `dxf` crate reports malformed files; this reader only looks).
pub fn pairs(bytes: &[u8]) -> Vec<Pair<'_>> {
    match bytes.strip_prefix(BINARY_SENTINEL) {
        Some(rest) => binary_pairs(rest),
        None => ascii_pairs(bytes),
    }
}

fn ascii_pairs(bytes: &[u8]) -> Vec<Pair<'_>> {
    match std::str::from_utf8(bytes) {
        Ok(text) => ascii_text_pairs(text, std::borrow::Cow::Borrowed),
        // not UTF-8 (an ANSI code page): values become owned, lossy strings
        Err(_) => {
            let text = String::from_utf8_lossy(bytes);
            ascii_text_pairs(&text, |v| std::borrow::Cow::Owned(v.to_string()))
        }
    }
}

fn ascii_text_pairs<'t, 'b>(
    text: &'t str,
    own: impl Fn(&'t str) -> std::borrow::Cow<'b, str>,
) -> Vec<Pair<'b>> {
    let mut out = Vec::new();
    let mut lines = text.lines().map(str::trim).enumerate();
    while let (Some((_, code)), Some((i, value))) = (lines.next(), lines.next()) {
        let Ok(code) = code.parse::<i32>() else {
            break;
        };
        out.push(Pair {
            code,
            value: own(value),
            line: u32::try_from(i + 1).ok(),
        });
    }
    out
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

fn binary_pairs(b: &[u8]) -> Vec<Pair<'_>> {
    // R13 and later write 2-byte codes: the first pair (0, "SECTION") then starts 00 00
    let two_byte_codes = b.get(1) == Some(&0);
    let mut out = Vec::new();
    let mut i = 0;
    let take = |i: &mut usize, n: usize| -> Option<&[u8]> {
        let s = b.get(*i..*i + n)?;
        *i += n;
        Some(s)
    };
    loop {
        let code = if two_byte_codes {
            match take(&mut i, 2) {
                Some(c) => i32::from(i16::from_le_bytes([c[0], c[1]])),
                None => break,
            }
        } else {
            match take(&mut i, 1) {
                Some([255]) => match take(&mut i, 2) {
                    Some(c) => i32::from(i16::from_le_bytes([c[0], c[1]])),
                    None => break,
                },
                Some(c) => i32::from(c[0]),
                None => break,
            }
        };
        let Some(kind) = kind(code) else {
            break;
        };
        let num = |i: &mut usize, n: usize| take(i, n).map(|s| s.to_vec());
        let value: std::borrow::Cow<'_, str> = match kind {
            Kind::Str => {
                let Some(len) = b.get(i..).and_then(|r| r.iter().position(|&c| c == 0)) else {
                    break;
                };
                let s = String::from_utf8_lossy(&b[i..i + len]);
                i += len + 1;
                s
            }
            Kind::F64 => match num(&mut i, 8) {
                Some(v) => f64::from_le_bytes(v.try_into().unwrap_or([0; 8]))
                    .to_string()
                    .into(),
                None => break,
            },
            Kind::I16 => match num(&mut i, 2) {
                Some(v) => i16::from_le_bytes([v[0], v[1]]).to_string().into(),
                None => break,
            },
            Kind::I32 => match num(&mut i, 4) {
                Some(v) => i32::from_le_bytes(v.try_into().unwrap_or([0; 4]))
                    .to_string()
                    .into(),
                None => break,
            },
            Kind::I64 => match num(&mut i, 8) {
                Some(v) => i64::from_le_bytes(v.try_into().unwrap_or([0; 8]))
                    .to_string()
                    .into(),
                None => break,
            },
            Kind::Bool => {
                let n = if two_byte_codes { 1 } else { 2 };
                match num(&mut i, n) {
                    Some(v) => (v.iter().any(|&x| x != 0) as i32).to_string().into(),
                    None => break,
                }
            }
            Kind::Bytes => {
                let Some(&len) = b.get(i) else {
                    break;
                };
                if take(&mut i, 1 + usize::from(len)).is_none() {
                    break;
                }
                std::borrow::Cow::Borrowed("")
            }
        };
        out.push(Pair {
            code,
            value,
            line: None,
        });
    }
    out
}

/// How the layer table shows one layer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct LayerState {
    /// Off: a negative colour number.
    pub off: bool,
    /// Frozen: bit 1 of flag 70.
    pub frozen: bool,
}

/// The layers of the LAYER table with their state, by name as written.
pub fn layer_states(pairs: &[Pair]) -> Vec<(String, LayerState)> {
    let mut out = Vec::new();
    let mut in_layer_table = false;
    let mut current: Option<(String, LayerState)> = None;
    let mut flush = |current: &mut Option<(String, LayerState)>| {
        if let Some((name, state)) = current.take() {
            if !name.is_empty() {
                out.push((name, state));
            }
        }
    };
    for (k, p) in pairs.iter().enumerate() {
        if p.code == 0 {
            flush(&mut current);
            if p.value == "TABLE" {
                in_layer_table = pairs
                    .get(k + 1)
                    .is_some_and(|n| n.code == 2 && n.value == "LAYER");
            } else if p.value == "ENDTAB" || p.value == "ENDSEC" {
                in_layer_table = false;
            } else if in_layer_table && p.value == "LAYER" {
                current = Some((String::new(), LayerState::default()));
            }
            continue;
        }
        let Some((name, state)) = current.as_mut() else {
            continue;
        };
        match p.code {
            2 => *name = p.value.to_string(),
            62 => state.off = p.value.trim().parse::<i32>().is_ok_and(|c| c < 0),
            70 => state.frozen = p.value.trim().parse::<i32>().is_ok_and(|f| f & 1 != 0),
            _ => {}
        }
    }
    flush(&mut current);
    out
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

/// The entities of the ENTITIES and BLOCKS sections whose type `keep` accepts.
pub fn entities(pairs: &[Pair], keep: impl Fn(&str) -> bool) -> Vec<ScannedEntity> {
    let mut out = Vec::new();
    let mut section = "";
    let mut block: Option<String> = None;
    let mut k = 0;
    while k < pairs.len() {
        let p = &pairs[k];
        k += 1;
        if p.code != 0 {
            continue;
        }
        if p.value == "SECTION" {
            section = match pairs.get(k) {
                Some(n) if n.code == 2 && n.value == "ENTITIES" => "ENTITIES",
                Some(n) if n.code == 2 && n.value == "BLOCKS" => "BLOCKS",
                _ => "",
            };
            continue;
        }
        if section.is_empty() {
            continue;
        }
        // the entity's own pairs, up to the next code 0
        let end = pairs[k..]
            .iter()
            .position(|q| q.code == 0)
            .map_or(pairs.len(), |n| k + n);
        let own = &pairs[k..end];
        let value = |code: i32| {
            own.iter()
                .find(|q| q.code == code)
                .map(|q| q.value.as_ref())
        };
        match p.value.as_ref() {
            "BLOCK" => block = value(2).map(str::to_string),
            "ENDBLK" | "ENDSEC" => block = None,
            kind if keep(kind) => out.push(ScannedEntity {
                kind: kind.to_string(),
                handle: value(5).unwrap_or("?").to_string(),
                layer: value(8).unwrap_or("?").to_string(),
                block: block.clone(),
                invisible: value(60).is_some_and(|v| v.trim().parse::<i32>().is_ok_and(|f| f != 0)),
                line: p.line,
            }),
            _ => {}
        }
        k = end;
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
        0\nENDTAB\n0\nENDSEC\n\
        0\nSECTION\n2\nBLOCKS\n0\nBLOCK\n8\n0\n2\nB1\n70\n0\n0\nHATCH\n5\n2A\n8\nX\n0\nENDBLK\n0\nENDSEC\n\
        0\nSECTION\n2\nENTITIES\n0\nHATCH\n5\n2B\n8\nY\n60\n1\n0\nLINE\n8\nZ\n0\nENDSEC\n0\nEOF\n";

    #[test]
    fn ascii_layer_states_and_scanned_entities() {
        let p = pairs(ASCII.as_bytes());
        let layers = layer_states(&p);
        let get = |n: &str| layers.iter().find(|(m, _)| m == n).map(|(_, s)| *s);
        assert_eq!(get("A"), Some(LayerState::default()));
        assert_eq!(
            get("OFF"),
            Some(LayerState {
                off: true,
                frozen: false
            })
        );
        assert_eq!(
            get("FROZEN"),
            Some(LayerState {
                off: false,
                frozen: true
            })
        );
        assert_eq!(
            get("BOTH"),
            Some(LayerState {
                off: true,
                frozen: true
            })
        );
        assert_eq!(layers.len(), 4);
        let hatches = entities(&p, |k| k == "HATCH");
        assert_eq!(hatches.len(), 2);
        assert_eq!(hatches[0].block.as_deref(), Some("B1"));
        assert_eq!(
            (hatches[0].handle.as_str(), hatches[0].layer.as_str()),
            ("2A", "X")
        );
        assert!(!hatches[0].invisible);
        assert_eq!(hatches[1].block, None);
        assert!(hatches[1].invisible);
        // the line of the type name: line 53 of the text
        let line = ASCII.lines().position(|l| l == "2B").map(|i| i as u32 - 1);
        assert_eq!(hatches[1].line, line);
    }

    #[test]
    fn binary_pairs_read_like_ascii() {
        // R13+ binary: 2-byte codes, NUL-terminated strings, little-endian numbers
        let mut b = BINARY_SENTINEL.to_vec();
        let mut s = |code: i16, v: &str| {
            b.extend(code.to_le_bytes());
            b.extend(v.as_bytes());
            b.push(0);
        };
        s(0, "SECTION");
        s(2, "TABLES");
        s(0, "TABLE");
        s(2, "LAYER");
        s(0, "LAYER");
        s(2, "F");
        b.extend(70i16.to_le_bytes());
        b.extend(1i16.to_le_bytes());
        b.extend(62i16.to_le_bytes());
        b.extend((-7i16).to_le_bytes());
        b.extend(10i16.to_le_bytes());
        b.extend(2.5f64.to_le_bytes());
        b.extend(290i16.to_le_bytes());
        b.push(1);
        let mut s = |code: i16, v: &str| {
            b.extend(code.to_le_bytes());
            b.extend(v.as_bytes());
            b.push(0);
        };
        s(0, "ENDTAB");
        s(0, "ENDSEC");
        s(0, "EOF");
        let p = pairs(&b);
        assert_eq!(p.len(), 13);
        assert_eq!(p[7].value, "-7");
        assert_eq!(p[8].value, "2.5");
        assert_eq!(
            layer_states(&p),
            vec![(
                "F".to_string(),
                LayerState {
                    off: true,
                    frozen: true
                }
            )]
        );
    }

    #[test]
    fn truncated_or_garbage_input_stops_quietly() {
        assert!(pairs(b"0\nSECTION\nnot a code\nx\n").len() == 1);
        let mut b = BINARY_SENTINEL.to_vec();
        b.extend([0, 0, b'S']);
        assert!(pairs(&b).is_empty());
        assert!(layer_states(&pairs(&[0xff; 64])).is_empty());
    }
}
