//! The version upgrade rules: a file older than Mitsuba 2.0 (0.4 to 0.6, 1.x) is read as
//! Mitsuba 3 reads it, its property lists upgraded element by element (`upgrade_v1`). Files of
//! 2.x and 3.x need no upgrade. Each file is upgraded by its own `<scene version>`, an
//! `<include>`d one too.

use super::object::{Obj, Prop};
use glam::{DMat4, DVec3};

/// Mitsuba 3's upgrade of a property list from a file older than 2.0 (its `upgrade_from_v1`):
/// camelCase names to snake_case, a diffuse BSDF's `diffuse_reflectance` to `reflectance`,
/// and `uoffset`, `voffset`, `uscale`, `vscale` to a `to_uv` transform. Unlike Mitsuba 3,
/// nothing is dropped: a medium's `sigma_s` and `sigma_a` stay (Mitsuba 0.6 honours them).
pub(super) fn upgrade_v1(o: &mut Obj) {
    for (name, _, _) in &mut o.props {
        *name = camel_to_snake(name);
    }
    if o.ty == "diffuse" {
        for (name, _, _) in &mut o.props {
            if name == "diffuse_reflectance" {
                *name = "reflectance".into();
            }
        }
    }
    let mut offset = DVec3::ZERO;
    let mut scale = DVec3::ONE;
    let mut any = None;
    o.props.retain(|(name, p, line)| {
        let x = match p {
            Prop::Float(x) => *x,
            Prop::Int(i) => *i as f64,
            _ => return true,
        };
        match name.as_str() {
            "uoffset" => offset.x = x,
            "voffset" => offset.y = x,
            "uscale" => scale.x = x,
            "vscale" => scale.y = x,
            _ => return true,
        }
        any = Some(*line);
        false
    });
    if let Some(line) = any {
        let m = DMat4::from_scale(scale) * DMat4::from_translation(offset);
        o.props.push(("to_uv".into(), Prop::Transform(m), line));
    }
}

/// Mitsuba 3's `camel_to_underscore_case`: an upper-case letter after a lower-case one starts
/// a new word (`toWorld` to `to_world`), and the upper-case letters right after it stay in
/// that word (`intIOR` to `int_ior`).
pub(super) fn camel_to_snake(name: &str) -> String {
    let c: Vec<char> = name.chars().collect();
    let mut out = String::with_capacity(name.len() + 4);
    let mut i = 0;
    while i < c.len() {
        if i > 0 && c[i - 1].is_ascii_lowercase() && c[i].is_ascii_uppercase() {
            out.push('_');
            out.push(c[i].to_ascii_lowercase());
            while i + 1 < c.len() && c[i + 1].is_ascii_uppercase() {
                i += 1;
                out.push(c[i].to_ascii_lowercase());
            }
        } else {
            out.push(c[i]);
        }
        i += 1;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn camel_case_becomes_snake_case_as_in_mitsuba_3() {
        for (old, new) in [
            ("toWorld", "to_world"),
            ("intIOR", "int_ior"),
            ("sampleCount", "sample_count"),
            ("sigmaS", "sigma_s"),
            ("specularReflectance", "specular_reflectance"),
            ("globalLookupRadius", "global_lookup_radius"),
            ("max_depth", "max_depth"),
            ("fov", "fov"),
        ] {
            assert_eq!(camel_to_snake(old), new);
        }
    }
}
