//! `blend`: a weighted sum of materials (Mitsuba's `blendbsdf`, two materials, and Mitsuba
//! 0.6's `mixturebsdf`, any number), made as pbrt-v4's `MixMaterial` makes it: each hit takes
//! ONE of the components, chosen with probability its weight by a hash of the hit's position
//! and texture coordinates, so that the mean over the surface is the weighted sum while the
//! lobe stays one kind's (no lobe of lobes in the integrators' inner loops). The same point
//! always takes the same component, so that the strategies of the bidirectional integrators
//! see one BSDF there.
//!
//! | Parameter   | Type                   | Meaning                                                     | Default |
//! |-------------|------------------------|-------------------------------------------------------------|---------|
//! | `materials` | array of tables        | the components, each a material table (its `type` and parameters) | (required) |
//! | `weight`    | number / RGB / texture | with two components: the second's weight w (the mean of a colour's channels, clamped to [0, 1]); the first's is 1 - w | `0.5` |
//! | `weights`   | array of numbers       | instead of `weight`: one weight (>= 0) per component; a sum below 1 leaves the rest absorbed | |
//! | `ensure_energy_conservation` | bool  | with `weights` summing above 1: scale them to sum to 1 (with a warning), as Mitsuba 0.6 does; false is refused (the sum would create energy) | `true` |
//!
//! A `null` component is refused: the scene's visibility takes a null material's surfaces
//! for holes everywhere, not at some points.

use super::phong::{channel_mean, scalar_texture};
use super::{Lobe, Material, nested_material};
use crate::Rgb;
use crate::props::Properties;
use crate::registry::Factory;
use crate::sampling::splitmix64;
use crate::texture::Texture;
use crate::texture::TextureEvalContext;
use crate::value::Value;
use glam::{Vec2, Vec3};

/// How the components are weighted.
#[derive(Clone, Debug)]
pub enum BlendWeights {
    /// Two components, the second's weight (the mean of the texture's channels, clamped to
    /// [0, 1]) read at the hit.
    Blend(Texture),
    /// One constant weight per component, summing to at most 1.
    Mixture(Vec<f32>),
}

#[derive(Clone, Debug)]
pub struct BlendMaterial {
    pub weights: BlendWeights,
    /// The components, none of them `Null` (nested blends allowed).
    pub components: Vec<Material>,
}

/// A number in [0, 1) that hashes a hit's position and texture coordinates.
#[inline]
fn unit(h: u64) -> f32 {
    (h >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
}

/// The hash of a hit at `p` with texture coordinates `uv`.
#[inline]
pub fn hit_hash(p: Vec3, uv: Vec2) -> u64 {
    let mut h = 0x6A09_E667_F3BC_C909u64;
    for x in [p.x, p.y, p.z, uv.x, uv.y] {
        // +0 and -0 alike.
        h = splitmix64(h ^ u64::from((x + 0.0).to_bits()));
    }
    h
}

impl BlendMaterial {
    /// The component a number `u` in [0, 1) chooses at `ctx`: the second of a blend when
    /// u < w, the i-th of a mixture when u falls in its share of [0, 1) (each share its
    /// weight long); None when u falls beyond the weights' sum (absorbed).
    #[inline]
    pub fn choose(&self, u: f32, ctx: TextureEvalContext) -> Option<&Material> {
        match &self.weights {
            BlendWeights::Blend(w) => {
                let w = channel_mean(w.at(ctx));
                Some(&self.components[usize::from(u < w)])
            }
            BlendWeights::Mixture(weights) => {
                let mut sum = 0.0;
                for (w, m) in weights.iter().zip(&self.components) {
                    sum += w;
                    if u < sum {
                        return Some(m);
                    }
                }
                None
            }
        }
    }

    /// The material a hit at `p` with texture coordinates `uv` takes: nested blends resolved,
    /// each by a hash of its own (the outer hash hashed again), so that their choices are
    /// independent. None: absorbed.
    pub fn resolve(&self, p: Vec3, ctx: TextureEvalContext) -> Option<&Material> {
        let mut h = hit_hash(p, ctx.uv);
        let mut blend = self;
        loop {
            match blend.choose(unit(h), ctx)? {
                Material::Blend(inner) => {
                    blend = inner;
                    h = splitmix64(h);
                }
                m => return Some(m),
            }
        }
    }

    /// The lobe the hit takes and whether it is mirrored from below (see
    /// [`Material::lobe_at`]); an absorbed hit takes a black diffuse lobe.
    #[inline(never)]
    pub(crate) fn lobe_at(&self, p: Vec3, ctx: TextureEvalContext) -> Option<(Lobe, bool)> {
        match self.resolve(p, ctx) {
            Some(m) => m.lobe_at(p, ctx),
            None => Some((
                Lobe::Diffuse(super::diffuse::DiffuseBxdf {
                    reflectance: Rgb::ZERO,
                    twosided: true,
                }),
                false,
            )),
        }
    }

    /// True when every component scatters only in Dirac deltas.
    pub fn is_delta(&self) -> bool {
        self.components.iter().all(Material::is_delta)
    }

    /// True when any component bounds a volume of its own.
    pub fn encloses_volume(&self) -> bool {
        self.components.iter().any(Material::encloses_volume)
    }
}

pub const FACTORY: Factory<Material> = Factory {
    name: "blend",
    description: "a weighted sum of materials (Mitsuba's blendbsdf and mixturebsdf), one chosen per hit",
    create: |m, nested, resources| {
        let Some(node) = m.node("materials") else {
            return Err(m.error(
                "materials",
                "missing: the components, an array of material tables",
            ));
        };
        let Value::Array(items) = &node.value else {
            return Err(m.error("materials", "expected an array of material tables"));
        };
        let mut components = Vec::with_capacity(items.len());
        for (i, item) in items.iter().enumerate() {
            let path = format!("{}[{i}]", m.key_path("materials"));
            let bag = Properties::new(m.file(), &path, item)?;
            let material = nested_material(&bag, nested, resources)?;
            if material.is_null() {
                return Err(bag.error(
                    "type",
                    "a null material cannot be a component of a blend (a null surface is a hole everywhere or nowhere)",
                ));
            }
            nested.push(bag);
            components.push(material);
        }
        if components.is_empty() {
            return Err(m.error("materials", "no components: give at least one material"));
        }
        let weights = if m.has("weights") {
            if m.has("weight") {
                return Err(m.error(
                    "weight",
                    "give either `weight` (two components) or `weights`",
                ));
            }
            let Some(Value::Array(ws)) = m.node("weights").map(|n| &n.value) else {
                return Err(m.error("weights", "expected an array of numbers"));
            };
            let mut weights = Vec::with_capacity(ws.len());
            for w in ws {
                let w = match w.value {
                    Value::Float(x) => x as f32,
                    Value::Int(i) => i as f32,
                    _ => return Err(m.error("weights", "expected an array of numbers")),
                };
                if !(w >= 0.0 && w.is_finite()) {
                    return Err(m.error("weights", format!("must be >= 0, found {w}")));
                }
                weights.push(w);
            }
            if weights.len() != components.len() {
                return Err(m.error(
                    "weights",
                    format!(
                        "{} weights for {} materials: give one per material",
                        weights.len(),
                        components.len()
                    ),
                ));
            }
            let sum: f32 = weights.iter().sum();
            if sum <= 0.0 {
                return Err(m.error("weights", "must sum to more than 0"));
            }
            let conserve = m.bool("ensure_energy_conservation", true)?;
            if sum > 1.0 {
                if !conserve {
                    return Err(m.error(
                        "ensure_energy_conservation",
                        format!(
                            "false with weights summing to {sum} > 1 is not supported (the material would create energy)"
                        ),
                    ));
                }
                resources.warn(
                    m,
                    "weights",
                    format!("sum to {sum} > 1: scaled to sum to 1, as Mitsuba 0.6 does"),
                );
                for w in &mut weights {
                    *w /= sum;
                }
            }
            BlendWeights::Mixture(weights)
        } else {
            if components.len() != 2 {
                return Err(m.error(
                    "materials",
                    format!(
                        "{} materials with `weight`: a blend has two (or give `weights`, one per material)",
                        components.len()
                    ),
                ));
            }
            let w = scalar_texture(m, "weight", 0.5, resources)?;
            BlendWeights::Blend(w)
        };
        Ok(Box::new(Material::Blend(Box::new(BlendMaterial {
            weights,
            components,
        }))))
    },
};
