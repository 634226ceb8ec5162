//! `--set key=value` overrides, applied to the parsed TOML document before
//! it is read, so that they go through the same checks as the file.
//!
//! A key is a dotted path `a.b.c`, its last part possibly `name[i]` (one
//! element of an array); the value is read as a TOML value, else as a bare
//! string.

use super::ProblemError;

/// The text with every `a.b.c=value` applied; the value is read as a TOML
/// value (number, boolean, array, inline table, quoted string), else as a
/// bare string.
pub(super) fn apply_overrides(text: &str, overrides: &[String]) -> Result<String, ProblemError> {
    if overrides.is_empty() {
        return Ok(text.to_string());
    }
    let mut doc: toml::Table = text
        .parse()
        .map_err(|e: toml::de::Error| ProblemError::Parse(e.to_string()))?;
    for assignment in overrides {
        let fail = |message: &str| ProblemError::Override {
            assignment: assignment.clone(),
            message: message.into(),
        };
        let (key, raw) = assignment
            .split_once('=')
            .ok_or_else(|| fail("expected key=value"))?;
        set_key(&mut doc, key, parse_value(raw.trim())).map_err(|m| fail(&m))?;
    }
    toml::to_string(&doc).map_err(|e| ProblemError::Parse(e.to_string()))
}

/// Sets the dotted `key` (`a.b.c`, the last part possibly `name[i]`) of
/// `doc` to `value`, creating missing tables; an indexed element must
/// exist. The error says why the key cannot be set.
pub(crate) fn set_key(doc: &mut toml::Table, key: &str, value: toml::Value) -> Result<(), String> {
    let path: Vec<&str> = key.trim().split('.').map(str::trim).collect();
    if path.iter().any(|p| p.is_empty()) {
        return Err("empty key".into());
    }
    let (last, parents) = path.split_last().expect("non-empty path");
    let mut table = doc;
    for part in parents {
        if let Some((name, i)) = indexed(part) {
            // One table of an array of tables (`loads.point[0].force[1]`):
            // it must exist.
            let list = table
                .get_mut(name)
                .and_then(toml::Value::as_array_mut)
                .ok_or_else(|| format!("`{name}` is not an array of tables"))?;
            let len = list.len();
            table = list
                .get_mut(i)
                .ok_or_else(|| format!("`{name}` has {len} tables, no [{i}]"))?
                .as_table_mut()
                .ok_or_else(|| format!("`{part}` is not a table"))?;
            continue;
        }
        let entry = table
            .entry((*part).to_string())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        table = entry
            .as_table_mut()
            .ok_or_else(|| format!("`{part}` is not a table"))?;
    }
    match indexed(last) {
        Some((name, i)) => {
            let list = table
                .get_mut(name)
                .and_then(toml::Value::as_array_mut)
                .ok_or_else(|| format!("`{name}` is not an array"))?;
            let len = list.len();
            *list
                .get_mut(i)
                .ok_or_else(|| format!("`{name}` has {len} elements, no [{i}]"))? = value;
        }
        None => {
            table.insert((*last).to_string(), value);
        }
    }
    Ok(())
}

/// The value at the dotted `key` of `doc`, if there is one.
pub(crate) fn get_key<'d>(doc: &'d toml::Table, key: &str) -> Option<&'d toml::Value> {
    let path: Vec<&str> = key.trim().split('.').map(str::trim).collect();
    let (last, parents) = path.split_last()?;
    let mut table = doc;
    for part in parents {
        table = match indexed(part) {
            Some((name, i)) => table.get(name)?.as_array()?.get(i)?.as_table()?,
            None => table.get(*part)?.as_table()?,
        };
    }
    match indexed(last) {
        Some((name, i)) => table.get(name)?.as_array()?.get(i),
        None => table.get(*last),
    }
}

/// `name[i]` → (name, i): one element of an array, as in
/// `--set energy.stiffness[0]=4` (what `[sweep]` axes and continuation
/// parameters are named).
pub(super) fn indexed(part: &str) -> Option<(&str, usize)> {
    let (name, rest) = part.split_once('[')?;
    let i = rest.strip_suffix(']')?.trim().parse().ok()?;
    Some((name.trim(), i))
}

pub(super) fn parse_value(raw: &str) -> toml::Value {
    format!("v = {raw}")
        .parse::<toml::Table>()
        .ok()
        .and_then(|mut t| t.remove("v"))
        .unwrap_or_else(|| toml::Value::String(raw.to_string()))
}
