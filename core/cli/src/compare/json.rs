//! The numbers of `foton compare` as JSON (<output stem>.json): per integrator its name,
//! description, spp, seconds, errors against the reference (rel_mse, bias and the mean LDR-FLIP
//! `flip`; null without one), the values --time chose, the error curve and its image; with
//! --consistency, the outcome of each pair's test.

use super::Entry;
use super::consistency::Pair;
use std::path::Path;

/// `s` as a JSON string literal (quotes, backslashes and control characters escaped).
pub(crate) fn json_string(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            c if (c as u32) < 0x20 => out.push_str(&format!("\\u{:04x}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// `x` as a JSON number; `null` when it is not finite.
pub(crate) fn json_number(x: f64) -> String {
    if x.is_finite() {
        format!("{x}")
    } else {
        "null".into()
    }
}

fn json_settings(settings: &[String]) -> String {
    let items: Vec<String> = settings.iter().map(|x| json_string(x)).collect();
    format!("[{}]", items.join(", "))
}

pub(super) fn json(
    scene: &Path,
    reference: Option<&Path>,
    time: Option<f64>,
    entries: &[Entry],
    consistency: Option<&[Pair]>,
) -> String {
    let file_name = |p: &Path| {
        p.file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
    };
    let mut s = String::from("{\n");
    s += &format!(
        "  \"scene\": {},\n",
        json_string(&scene.display().to_string())
    );
    s += &format!(
        "  \"reference\": {},\n",
        reference.map_or("null".into(), |r| json_string(&r.display().to_string()))
    );
    s += &format!("  \"time\": {},\n", time.map_or("null".into(), json_number));
    s += "  \"integrators\": [\n";
    for (i, e) in entries.iter().enumerate() {
        let (rel_mse, bias) = e
            .errors
            .map_or((f64::NAN, f64::NAN), |er| (er.rel_mse, er.bias));
        s += "    {\n";
        s += &format!("      \"name\": {},\n", json_string(&e.name));
        s += &format!("      \"description\": {},\n", json_string(&e.description));
        s += &format!(
            "      \"spp\": {},\n",
            e.spp.map_or("null".into(), |n| n.to_string())
        );
        s += &format!("      \"seconds\": {},\n", json_number(e.seconds));
        s += &format!("      \"rel_mse\": {},\n", json_number(rel_mse));
        s += &format!("      \"bias\": {},\n", json_number(bias));
        s += &format!(
            "      \"flip\": {},\n",
            e.flip.map_or("null".into(), json_number)
        );
        s += &format!("      \"set\": {},\n", json_settings(&e.settings));
        if e.renders > 1 {
            s += &format!("      \"renders\": {},\n", e.renders);
        }
        if !e.curve.is_empty() {
            s += "      \"curve\": [\n";
            for (j, p) in e.curve.iter().enumerate() {
                s += &format!(
                    "        {{\"budget\": {}, \"seconds\": {}, \"rel_mse\": {}, \"bias\": {}, \"set\": {}}}{}\n",
                    json_number(p.budget),
                    json_number(p.seconds),
                    json_number(p.errors.rel_mse),
                    json_number(p.errors.bias),
                    json_settings(&p.settings),
                    if j + 1 < e.curve.len() { "," } else { "" }
                );
            }
            s += "      ],\n";
        }
        s += &format!("      \"image\": {}\n", json_string(&file_name(&e.image)));
        s += if i + 1 < entries.len() {
            "    },\n"
        } else {
            "    }\n"
        };
    }
    s += "  ]";
    if let Some(pairs) = consistency {
        s += ",\n  \"consistency\": [\n";
        for (i, p) in pairs.iter().enumerate() {
            let o = &p.outcome;
            let biased: Vec<String> = p.biased.iter().map(|(n, _)| json_string(n)).collect();
            s += &format!(
                "    {{\"a\": {}, \"b\": {}, \"blocks_tested\": {}, \"blocks_differ\": {}, \"min_adjusted_p\": {}, \"differ\": {}, \"biased\": [{}]}}{}\n",
                json_string(&p.a),
                json_string(&p.b),
                o.tested(),
                o.differing(),
                o.min_adjusted_p().map_or("null".into(), json_number),
                p.differs(),
                biased.join(", "),
                if i + 1 < pairs.len() { "," } else { "" }
            );
        }
        s += "  ]";
    }
    s += "\n}\n";
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_escapes_strings_and_writes_null_for_missing_numbers() {
        assert_eq!(json_string("a\"b\\c\n"), "\"a\\\"b\\\\c\\n\"");
        assert_eq!(json_number(f64::NAN), "null");
        assert_eq!(json_number(0.0), "0");
        assert_eq!(json_number(0.25), "0.25");
    }
}
