//! Mutations of problem texts and result files: the seeded generator, the
//! problem texts to start from, and what a case changes in them.

use super::*;

/// A small deterministic generator (SplitMix64): the cases of a seed are
/// the same on every machine.
pub(crate) struct Rng(pub(crate) u64);

impl Rng {
    pub(crate) fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    pub(crate) fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
    pub(crate) fn chance(&mut self, p: f64) -> bool {
        ((self.next() >> 11) as f64 / (1u64 << 53) as f64) < p
    }
    pub(crate) fn pick<'a, T>(&mut self, v: &'a [T]) -> &'a T {
        &v[self.below(v.len())]
    }
}

/// The shipped problems and the bad-input corpus, by name.
pub(crate) fn seeds() -> Vec<(String, String)> {
    let mut out = vec![];
    for dir in ["problems", "crates/cosserat/tests/corpus"] {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(Path::new(ROOT).join(dir))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .collect();
        entries.sort();
        for p in entries {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            out.push((name, std::fs::read_to_string(&p).unwrap()));
        }
    }
    out
}

/// Dotted keys of every number, string, boolean and array in a problem
/// text (array elements as `key[i]`): the targets of `--set`.
pub(crate) fn keys(text: &str) -> Vec<String> {
    fn walk(prefix: &str, v: &toml::Value, out: &mut Vec<String>) {
        match v {
            toml::Value::Table(t) => {
                for (k, v) in t {
                    let key = if prefix.is_empty() {
                        k.clone()
                    } else {
                        format!("{prefix}.{k}")
                    };
                    walk(&key, v, out);
                }
            }
            toml::Value::Array(a) => {
                out.push(prefix.to_string());
                for (i, x) in a.iter().enumerate() {
                    if !x.is_table() {
                        out.push(format!("{prefix}[{i}]"));
                    }
                }
            }
            _ => out.push(prefix.to_string()),
        }
    }
    let mut out = vec![];
    if let Ok(t) = toml::from_str::<toml::Table>(text) {
        walk("", &toml::Value::Table(t), &mut out);
    }
    out
}

pub(crate) const EXTREMES: [&str; 30] = [
    "0",
    "-0.0",
    "-1",
    "1",
    "0.5",
    "2",
    "1e-320",
    "5e-324",
    "1e-308",
    "1e-16",
    "1e-12",
    "1e-6",
    "1e3",
    "1e6",
    "1e9",
    "1e12",
    "5e11",
    "1e15",
    "1e100",
    "1e308",
    "-1e308",
    "9223372036854775807",
    "-9223372036854775808",
    "18446744073709551615",
    "4294967296",
    "100000",
    "1000000",
    "nan",
    "inf",
    "-inf",
];

pub(crate) const WRONG_TYPES: [&str; 10] = [
    "\"text\"",
    "true",
    "[]",
    "[1, 2]",
    "[1, 2, 3, 4]",
    "[[1, 2], [3]]",
    "{ a = 1 }",
    "\"\"",
    "1979-05-27T07:32:00Z",
    "[\"a\", 1]",
];

/// The lines of a text that assign a value.
pub(crate) fn assignments(lines: &[&str]) -> Vec<usize> {
    lines
        .iter()
        .enumerate()
        .filter(|(_, l)| {
            let t = l.trim_start();
            !t.starts_with('#') && !t.starts_with('[') && t.contains('=')
        })
        .map(|(i, _)| i)
        .collect()
}

/// Spans of number-like tokens in `s` (after the first `=`).
pub(crate) fn number_spans(s: &str) -> Vec<(usize, usize)> {
    let start = s.find('=').map_or(0, |i| i + 1);
    let b = s.as_bytes();
    let mut out = vec![];
    let mut i = start;
    while i < b.len() {
        let begins = (b[i].is_ascii_digit()
            || (b[i] == b'-' && i + 1 < b.len() && b[i + 1].is_ascii_digit()))
            && (i == 0 || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_'));
        if begins {
            let mut j = i + 1;
            while j < b.len()
                && (b[j].is_ascii_digit() || matches!(b[j], b'.' | b'e' | b'E' | b'_'))
                || (j < b.len() && matches!(b[j], b'+' | b'-') && matches!(b[j - 1], b'e' | b'E'))
            {
                j += 1;
            }
            out.push((i, j));
            i = j;
        } else {
            i += 1;
        }
    }
    out
}

/// One mutation of a problem text; returns the new bytes and its name.
pub(crate) fn mutate(rng: &mut Rng, text: &str) -> (Vec<u8>, String) {
    let lines: Vec<&str> = text.lines().collect();
    let assigned = assignments(&lines);
    let mut owned: Vec<String> = lines.iter().map(std::string::ToString::to_string).collect();
    match rng.below(10) {
        0 | 1 => extreme_number(rng, text, &lines, &assigned, owned),
        2 => wrong_type(rng, text, &lines, &assigned, owned),
        3 => array_resized(rng, text, &lines, &assigned, owned),
        4 => {
            // A line deleted (a key, or a table header).
            let i = rng.below(lines.len());
            owned.remove(i.min(owned.len().saturating_sub(1)));
            (rebuild(&owned), format!("line {} deleted", i + 1))
        }
        5 => {
            // A line duplicated (a duplicate key or table).
            let i = rng.below(lines.len());
            let l = owned[i.min(owned.len().saturating_sub(1))].clone();
            owned.insert(i, l);
            (rebuild(&owned), format!("line {} duplicated", i + 1))
        }
        6 => {
            // Truncated at a byte (possibly inside a character).
            let cut = rng.below(text.len());
            (
                text.as_bytes()[..cut].to_vec(),
                format!("truncated at byte {cut}"),
            )
        }
        7 => {
            // Byte noise.
            let mut b = text.as_bytes().to_vec();
            let n = 1 + rng.below(4);
            for _ in 0..n {
                let i = rng.below(b.len());
                b[i] = (rng.next() & 0xff) as u8;
            }
            (b, format!("{n} bytes changed"))
        }
        8 => table_header_changed(rng, text, &lines, owned),
        _ => {
            // A huge comment: a file over any sane size.
            let mut b = text.as_bytes().to_vec();
            b.extend(std::iter::repeat_n(b'#', 3 << 20));
            (b, "3 MiB file".into())
        }
    }
}

/// The text of edited lines.
fn rebuild(lines: &[String]) -> Vec<u8> {
    lines.join("\n").into_bytes()
}

/// A number replaced by an extreme.
fn extreme_number(
    rng: &mut Rng,
    text: &str,
    lines: &[&str],
    assigned: &[usize],
    mut owned: Vec<String>,
) -> (Vec<u8>, String) {
    let candidates: Vec<(usize, (usize, usize))> = assigned
        .iter()
        .flat_map(|&i| number_spans(lines[i]).into_iter().map(move |s| (i, s)))
        .collect();
    if candidates.is_empty() {
        return (text.as_bytes().to_vec(), "unchanged".into());
    }
    let (i, (a, b)) = *rng.pick(&candidates);
    let v = rng.pick(&EXTREMES);
    owned[i] = format!("{}{v}{}", &lines[i][..a], &lines[i][b..]);
    (rebuild(&owned), format!("line {} number → {v}", i + 1))
}

/// A value of the wrong type.
fn wrong_type(
    rng: &mut Rng,
    text: &str,
    lines: &[&str],
    assigned: &[usize],
    mut owned: Vec<String>,
) -> (Vec<u8>, String) {
    let Some(&i) = (!assigned.is_empty()).then(|| rng.pick(assigned)) else {
        return (text.as_bytes().to_vec(), "unchanged".into());
    };
    let key = lines[i].split('=').next().unwrap_or("");
    let v = rng.pick(&WRONG_TYPES);
    owned[i] = format!("{key}= {v}");
    (rebuild(&owned), format!("line {} → {v}", i + 1))
}

/// An array one longer or one shorter.
fn array_resized(
    rng: &mut Rng,
    text: &str,
    lines: &[&str],
    assigned: &[usize],
    mut owned: Vec<String>,
) -> (Vec<u8>, String) {
    let arrays: Vec<usize> = assigned
        .iter()
        .copied()
        .filter(|&i| lines[i].contains('[') && lines[i].contains(']'))
        .collect();
    let Some(&i) = (!arrays.is_empty()).then(|| rng.pick(&arrays)) else {
        return (text.as_bytes().to_vec(), "unchanged".into());
    };
    let l = lines[i];
    let close = l.rfind(']').unwrap();
    let longer = rng.chance(0.5);
    owned[i] = if longer {
        format!("{}, 1.0{}", &l[..close], &l[close..])
    } else {
        match l[..close].rfind(',') {
            Some(c) => format!("{}{}", &l[..c], &l[close..]),
            None => format!("{}[]", &l[..=l.find('=').unwrap()]),
        }
    };
    let how = if longer { "longer" } else { "shorter" };
    (rebuild(&owned), format!("line {} array {how}", i + 1))
}

/// A table header renamed or repeated.
fn table_header_changed(
    rng: &mut Rng,
    text: &str,
    lines: &[&str],
    mut owned: Vec<String>,
) -> (Vec<u8>, String) {
    let headers: Vec<usize> = lines
        .iter()
        .enumerate()
        .filter(|(_, l)| l.trim_start().starts_with('['))
        .map(|(i, _)| i)
        .collect();
    let Some(&i) = (!headers.is_empty()).then(|| rng.pick(&headers)) else {
        return (text.as_bytes().to_vec(), "unchanged".into());
    };
    if rng.chance(0.5) {
        owned.push(lines[i].to_string());
        (rebuild(&owned), format!("table of line {} repeated", i + 1))
    } else {
        owned[i] = "[nonsense]".into();
        (rebuild(&owned), format!("table of line {} renamed", i + 1))
    }
}

/// `--set` overrides with extreme or wrong values on the text's own keys.
pub(crate) fn overrides(rng: &mut Rng, text: &str) -> Vec<String> {
    let keys = keys(text);
    let mut out = vec![];
    if keys.is_empty() {
        return out;
    }
    for _ in 0..=rng.below(2) {
        let key = rng.pick(&keys);
        let value = if rng.chance(0.75) {
            rng.pick(&EXTREMES).to_string()
        } else {
            rng.pick(&WRONG_TYPES).to_string()
        };
        out.push("--set".into());
        out.push(format!("{key}={value}"));
    }
    out
}

/// An HDF5 file made hostile: truncated or with bytes changed.
pub(crate) fn damaged(rng: &mut Rng, bytes: &[u8]) -> (Vec<u8>, String) {
    let mut b = bytes.to_vec();
    if rng.chance(0.5) {
        let cut = rng.below(b.len());
        b.truncate(cut);
        (b, format!("truncated at {cut}"))
    } else {
        let n = 1 + rng.below(8);
        for _ in 0..n {
            let i = rng.below(b.len());
            b[i] = (rng.next() & 0xff) as u8;
        }
        (b, format!("{n} bytes changed"))
    }
}
