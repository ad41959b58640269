//! `<integrator>`: the foton plugin that renders Mitsuba's integrator, and its parameters
//! translated (Mitsuba's path-segment depths to foton's scattering events; a photon mapper's
//! budgets and radii). Read after the rest of the scene, since a photon mapper in a scene with
//! media is foton's volumetric one.

use super::object::{Obj, Prop, show};
use super::upgrade::camel_to_snake;
use super::{Reader, at, table_mut};
use foton_core::error::Result;
use foton_core::value::Value;

impl Reader {
    /// Mitsuba's integrator: the foton plugin that renders it, its parameters translated
    /// (each one foton has no equivalent for is a warning). Read after the rest of the scene.
    pub(super) fn integrator(&mut self, mut o: Obj) -> Result<()> {
        // Mitsuba 3 reads integrators' names as written; 0.6 files are upgraded. Accept the
        // 0.6 spelling in either (older exporters mix them).
        for (name, _, _) in &mut o.props {
            *name = camel_to_snake(name);
        }
        if matches!(o.ty.as_str(), "moment" | "stokes" | "aov") {
            return self.wrapper(o);
        }
        let has_media = !self.media.is_empty();
        let mitsuba = match self.fork_integrator(&mut o)? {
            Some(m) => m,
            None => o.ty.as_str(),
        };
        let Some(mapped) = foton_integrator(mitsuba, has_media) else {
            o.props.clear();
            let message = if MITSUBA_INTEGRATORS.contains(&o.ty.as_str()) {
                format!(
                    "integrator `{}` is not supported; foton renders path, volpath, volpath_simple, volpathmis, direct, photonmapper, sppm, ppm, bdpt, ptracer and the differentiable prb, prb_basic, prb_projective, prbvolpath and direct_projective",
                    o.ty
                )
            } else {
                format!(
                    "unknown integrator `{}`{}",
                    o.ty,
                    foton_core::error::suggestion(&o.ty, MITSUBA_INTEGRATORS.iter().copied())
                )
            };
            return self.unsupported(&o, &message);
        };
        let line = o.line;
        // A meter is reached only by paths traced from it: the path tracer measures what the
        // others converge to.
        let name = match self.meter {
            Some(meter) if mapped != "path" => {
                let meter = super::sensor::a_meter(meter);
                self.note(
                    &o,
                    &format!(
                        "rendered by path: the sensor is {meter}, which foton measures with paths traced from it (the value {} converges to)",
                        o.ty
                    ),
                );
                "path"
            }
            _ => mapped,
        };
        table_mut(&mut self.root, "render").insert("integrator", at(Value::Str(name.into()), line));
        if o.ty == "ptracer" && name == "bdpt" {
            self.note(
                &o,
                "rendered by bdpt, whose light-tracing strategy is the particle tracer's (with the others it converges to the same image)",
            );
        }
        if o.ty == "ppm" {
            self.note(
                &o,
                "rendered by sppm (the stochastic variant of progressive photon mapping converges to the same image)",
            );
        }
        // Mitsuba's max_depth counts path segments (1: emitters seen directly, 2: direct
        // light); foton's counts scattering events, one less. -1 is unbounded in both
        // Mitsubas: a cap no path reaches (Russian roulette ends them long before).
        // Mitsuba 3's differentiable integrators default to 6 (direct_projective: always 2).
        let max_depth = match o.ty.as_str() {
            "direct" | "direct_projective" => 2,
            ty if DIFFERENTIABLE.contains(&ty) => o.int("max_depth", 6)?,
            _ => o.int("max_depth", -1)?,
        };
        if DIFFERENTIABLE.contains(&o.ty.as_str()) {
            self.note(
                &o,
                "a differentiable integrator (Mitsuba 3's AD variants): rendered by path, whose image is its primal one; its gradient parameters are ignored",
            );
            for k in [
                "sppc",
                "sppp",
                "sppi",
                "guiding",
                "guiding_proj",
                "guiding_rounds",
                "project_seed",
            ] {
                self.ignored(&mut o, k, &|_| true, "");
            }
        }
        let bounces = match max_depth {
            -1 => 65_536,
            d if d >= 1 => d - 1,
            d => {
                return Err(o.error(format!(
                    "max_depth = {d}: renders nothing (1 is emitters seen directly, -1 unbounded)"
                )));
            }
        };
        table_mut(&mut self.root, "render").insert("max_depth", at(Value::Int(bounces), line));
        if o.boolean("hide_emitters", false)? {
            table_mut(&mut self.root, "render")
                .insert("hide_emitters", at(Value::Bool(true), line));
        }
        let mut params: Vec<(&str, Value)> = Vec::new();
        let rr = o.take("rr_depth");
        match name {
            "path" | "bdpt" => {
                // Mitsuba starts Russian roulette at path depth rr_depth (segments, 5 unless
                // the file says): foton counts scattering events.
                if let Some((p, l)) = rr {
                    o.props.push(("rr_depth".into(), p, l));
                }
                let rr = o.int("rr_depth", 5)?;
                params.push(("rr_depth", Value::Int(rr.max(1) - 1)));
            }
            _ => {
                if let Some((p, l)) = rr {
                    self.warn(
                        &o,
                        l,
                        &format!(
                            "`rr_depth` = {}: ignored ({name} traces photons with its own Russian roulette)",
                            show(&p)
                        ),
                    );
                }
            }
        }
        let same = |_: &Prop| false;
        self.ignored(
            &mut o,
            "strict_normals",
            &|p| matches!(p, Prop::Bool(false)),
            "ignored (foton does not end paths whose shading and geometric normals disagree)",
        );
        let noise = "ignored (it changes the noise, not the image: foton takes one sample per camera sample; raise spp)";
        // How Mitsuba 2 and 3 schedule the samples (passes, a time limit): not the image
        // foton renders with all of them.
        if !matches!(o.ty.as_str(), "sppm" | "ppm") {
            o.take("samples_per_pass");
        }
        // Mitsuba 2 and 3 stop rendering at `timeout` seconds (negative: none): render.time.
        let timeout_line = (o.props.iter())
            .find(|(n, _, _)| n == "timeout")
            .map_or(o.line, |(_, _, l)| *l);
        let timeout = o.float("timeout", -1.0)?;
        if timeout > 0.0 {
            table_mut(&mut self.root, "render")
                .insert("time", at(Value::Float(timeout), timeout_line));
        }
        // The parameters of an integrator foton renders by another (a meter's): ignored.
        let own = if name == mapped { o.ty.as_str() } else { "" };
        match own {
            "direct" => {
                for k in ["emitter_samples", "bsdf_samples", "shading_samples"] {
                    self.ignored(&mut o, k, &same, noise);
                }
            }
            "photonmapper" => {
                // Mitsuba 0.6's defaults, written out: the budgets and k are its meaning.
                let photons = |o: &mut Obj, k: &str| o.int(k, 250_000);
                params.push((
                    "global_photons",
                    Value::Int(photons(&mut o, "global_photons")?),
                ));
                params.push((
                    "caustic_photons",
                    Value::Int(photons(&mut o, "caustic_photons")?),
                ));
                let volume = photons(&mut o, "volume_photons")?;
                let lookup = o.int("lookup_size", 120)?;
                let k = o.int("global_lookup_size", lookup)?;
                params.push(("k", Value::Int(k)));
                let kc = o.int("caustic_lookup_size", lookup)?;
                if kc != k {
                    let why = format!(
                        "`caustic_lookup_size` = {kc}: foton's photon maps share one k ({k}, the global lookup size)"
                    );
                    self.warn(&o, line, &why);
                }
                let kv = o.int("volume_lookup_size", lookup)?;
                if name == "vpm" {
                    params.push(("volume_photons", Value::Int(volume)));
                    params.push(("k_volume", Value::Int(kv)));
                }
                // Mitsuba's lookup radii are fractions of the bounding sphere's radius.
                let rg = o.float("global_lookup_radius", 0.05)?;
                self.report.relative_radius = Some((name.to_string(), rg, line));
                if let Some((p, l)) = o.take("caustic_lookup_radius") {
                    let why = format!(
                        "`caustic_lookup_radius` = {}: foton's photon maps share one largest radius (the global lookup radius)",
                        show(&p)
                    );
                    self.warn(&o, l, &why);
                }
                for k in ["direct_samples", "glossy_samples"] {
                    self.ignored(&mut o, k, &same, noise);
                }
                self.ignored(
                    &mut o,
                    "max_specular_depth",
                    &same,
                    "ignored (foton follows specular bounces up to max_depth)",
                );
                for k in ["granularity", "gather_locally", "auto_cancel_gathering"] {
                    self.ignored(&mut o, k, &|_| true, "");
                }
            }
            "sppm" | "ppm" => {
                if let Some(n) = o
                    .take("photon_count")
                    .or_else(|| o.take("photons_per_iteration"))
                {
                    o.props.push(("photon_count".into(), n.0, n.1));
                    params.push((
                        "photons_per_iteration",
                        Value::Int(o.int("photon_count", 250_000)?),
                    ));
                }
                // 0 (Mitsuba's default): a radius guessed from the scene, as foton's is.
                let r = o.float("initial_radius", 0.0)?;
                if r > 0.0 {
                    params.push(("initial_radius", Value::Float(r)));
                }
                if let Some((p, l)) = o.take("alpha") {
                    o.props.push(("alpha".into(), p, l));
                    params.push(("alpha", Value::Float(o.float("alpha", 0.7)?)));
                }
                let passes = match o.take("passes").or_else(|| o.take("max_passes")) {
                    Some((p, l)) => {
                        o.props.push(("passes".into(), p, l));
                        Some((o.int("passes", -1)?, l))
                    }
                    None => None,
                };
                match passes {
                    Some((n, _)) if n >= 1 => params.push(("iterations", Value::Int(n))),
                    Some((n, l)) => {
                        let why = format!(
                            "passes = {n} (until stopped): foton runs its default number of iterations; give integrators.sppm.iterations or time"
                        );
                        self.warn(&o, l, &why);
                    }
                    None => {}
                }
                for k in ["granularity", "auto_cancel_gathering", "samples_per_pass"] {
                    self.ignored(&mut o, k, &|_| true, "");
                }
            }
            "bdpt" => {
                // lightImage = false: no strategy connects light paths to the camera.
                if !o.boolean("light_image", true)? {
                    params.push(("light_image", Value::Bool(false)));
                }
                // sampleDirect changes how often next-event strategies are taken, not the
                // image: foton's bdpt takes every strategy once per camera sample.
                self.ignored(
                    &mut o,
                    "sample_direct",
                    &|p| matches!(p, Prop::Bool(true)),
                    "ignored",
                );
            }
            "ptracer" => {
                for k in ["granularity", "brute_force"] {
                    self.ignored(&mut o, k, &|_| true, "");
                }
            }
            "" => {
                for (k, p, l) in std::mem::take(&mut o.props) {
                    self.warn(
                        &o,
                        l,
                        &format!("`{k}` = {}: ignored (path renders the meter)", show(&p)),
                    );
                }
            }
            _ => {}
        }
        let t = table_mut(table_mut(&mut self.root, "integrators"), name);
        for (k, v) in params {
            t.insert(k, at(v, line));
        }
        self.leftovers(&o)
    }
}

impl Reader {
    /// An integrator of one of Mitsuba's forks that estimates the image of one of Mitsuba's
    /// own: noted, its own parameters ignored (each a warning), and the Mitsuba integrator
    /// whose image it converges to returned, for its common parameters to be read as that
    /// one's. None for every other integrator.
    fn fork_integrator(&mut self, o: &mut Obj) -> Result<Option<&'static str>> {
        let Some(&(_, what)) = FORK_INTEGRATORS.iter().find(|(name, _)| *name == o.ty) else {
            return Ok(None);
        };
        let mitsuba = if o.ty == "vcm" {
            // VCM without merging is bidirectional path tracing (Georgiev et al. 2012).
            if o.boolean("enable_vm", true)? {
                "vcm"
            } else {
                "bdpt"
            }
        } else {
            "path"
        };
        self.note(
            o,
            &format!(
                "{what}, from a fork of Mitsuba: rendered by foton's {mitsuba}, which converges to the image it estimates"
            ),
        );
        const COMMON: [&str; 6] = [
            "max_depth",
            "rr_depth",
            "hide_emitters",
            "strict_normals",
            "samples_per_pass",
            "timeout",
        ];
        let own: Vec<_> = o
            .props
            .iter()
            .filter(|(name, p, _)| {
                !COMMON.contains(&name.as_str()) && !matches!(p, Prop::Object(_))
            })
            .map(|(name, _, _)| name.clone())
            .collect();
        for name in own {
            self.ignored(
                o,
                &name,
                &|_| false,
                "ignored (a parameter of the fork's integrator: how it samples, not what it renders)",
            );
        }
        Ok(Some(mitsuba))
    }
}

/// Integrators of Mitsuba's forks, each an estimator of the image one of Mitsuba's own
/// renders: path guiding, splitting and specular manifold sampling are path tracers that
/// sample otherwise; `vcm` merges as foton's does.
const FORK_INTEGRATORS: &[(&str, &str)] = &[
    (
        "guided_path",
        "practical path guiding's path tracer (Müller et al. 2017)",
    ),
    ("guidedpath", "a path tracer with path guiding"),
    ("path_guiding_integrator", "a path tracer with path guiding"),
    (
        "recursive_path",
        "EARS's path tracer with splitting and Russian roulette (Rath et al. 2022)",
    ),
    (
        "path_sms_ss",
        "a path tracer with specular manifold sampling (Zeltner et al. 2020)",
    ),
    (
        "path_sms_ms",
        "a path tracer with specular manifold sampling (Zeltner et al. 2020)",
    ),
    (
        "path_sms_teaser",
        "a path tracer with specular manifold sampling (Zeltner et al. 2020)",
    ),
    (
        "path_sms_glints",
        "a path tracer with specular manifold sampling of glints (Zeltner et al. 2020)",
    ),
    (
        "path_filtered_ss",
        "specular manifold sampling's comparison path tracer, which leaves out the caustic paths its manifold sampler renders (foton's path renders them all)",
    ),
    (
        "path_filtered_ms",
        "specular manifold sampling's comparison path tracer, which leaves out the caustic paths its manifold sampler renders (foton's path renders them all)",
    ),
    (
        "path_filtered_teaser",
        "specular manifold sampling's comparison path tracer, which leaves out the caustic paths its manifold sampler renders (foton's path renders them all)",
    ),
    (
        "restirgi",
        "ReSTIR GI, a path tracer reusing samples across pixels (Ouyang et al. 2021)",
    ),
    (
        "vcm",
        "vertex connection and merging (Georgiev et al. 2012)",
    ),
];

/// The integrators of Mitsuba 3 and 0.6 (for "not supported" against "unknown").
impl Reader {
    /// Mitsuba's `moment`, `stokes` and `aov`, which wrap integrators: the wrapped ones render
    /// the image, and `moment` adds their second moments as layers of the film, `stokes` the
    /// Stokes components S1 to S3 (zero in Mitsuba 3's RGB variants, which track no
    /// polarisation; foton tracks none either), `aov` the arbitrary output variables it names.
    /// foton renders the first it wraps; the extra layers are not written (a warning says so).
    fn wrapper(&mut self, mut o: Obj) -> Result<()> {
        // Mitsuba 3's aov without an integrator writes the AOVs alone: no image to render.
        let aovs = if o.ty == "aov" {
            o.string("aovs")?.unwrap_or_default()
        } else {
            String::new()
        };
        let nested = o
            .props
            .iter()
            .position(|(_, p, _)| matches!(p, Prop::Object(n) if n.tag == "integrator"));
        let Some(i) = nested else {
            if o.ty == "aov" {
                o.props.clear();
                return self.unsupported(
                    &o,
                    &format!("an aov integrator without an integrator writes only its AOVs ({aovs}), which foton does not render"),
                );
            }
            return Err(o.error(format!(
                "a {} integrator without the integrator it wraps",
                o.ty
            )));
        };
        let (_, Prop::Object(inner), _) = o.props.remove(i) else {
            unreachable!("the position of an object")
        };
        let more = o
            .props
            .iter()
            .filter(|(_, p, _)| matches!(p, Prop::Object(n) if n.tag == "integrator"))
            .count();
        o.props
            .retain(|(_, p, _)| !matches!(p, Prop::Object(n) if n.tag == "integrator"));
        self.leftovers(&o)?;
        let line = o.line;
        let aov_layers = format!("the AOV layers ({aovs}) are");
        let layers = if o.ty == "stokes" {
            "the Stokes layers S1 to S3 (foton tracks no polarisation) are"
        } else if o.ty == "aov" {
            aov_layers.as_str()
        } else if more > 0 {
            "the second-moment layers are"
        } else {
            "its second-moment layer is"
        };
        let what = if more > 0 {
            format!(
                "renders the image of the first integrator it wraps (<integrator type=\"{}\">); the other {more} and {layers} not written",
                inner.ty
            )
        } else {
            format!(
                "renders the image of the integrator it wraps (<integrator type=\"{}\">); {layers} not written",
                inner.ty
            )
        };
        self.warn(&o, line, &what);
        self.integrator(inner)
    }
}

/// Mitsuba 3's differentiable integrators (AD variants only), whose primal image is a path
/// tracer's (direct_projective's: direct lighting's).
const DIFFERENTIABLE: &[&str] = &[
    "prb",
    "prb_basic",
    "prb_projective",
    "prbvolpath",
    "direct_projective",
];

const MITSUBA_INTEGRATORS: &[&str] = &[
    "prb_basic",
    "path",
    "volpath",
    "volpath_simple",
    "volpathmis",
    "direct",
    "photonmapper",
    "sppm",
    "ppm",
    "bdpt",
    "ao",
    "aov",
    "depth",
    "moment",
    "stokes",
    "prb",
    "prbvolpath",
    "direct_projective",
    "prb_projective",
    "ptracer",
    "vpl",
    "irrcache",
    "adaptive",
    "field",
    "multichannel",
    "mlt",
    "pssmlt",
    "erpt",
];

/// The foton plugin that renders a Mitsuba integrator, or None (not supported). A photon
/// mapper in a scene with media is foton's volumetric one.
fn foton_integrator(mitsuba: &str, has_media: bool) -> Option<&'static str> {
    Some(match mitsuba {
        "path" | "volpath" | "volpath_simple" | "volpathmis" | "direct" => "path",
        "prb" | "prb_basic" | "prb_projective" | "prbvolpath" | "direct_projective" => "path",
        "photonmapper" if has_media => "vpm",
        "photonmapper" => "photon",
        "sppm" | "ppm" => "sppm",
        "bdpt" | "ptracer" => "bdpt",
        // Only a fork's (`fork_integrator`).
        "vcm" => "vcm",
        _ => return None,
    })
}

impl Reader {
    /// Mitsuba counts samples per pixel in 64 bits: files ask for 99999999999 with a
    /// `timeout` that ends the render. With a time limit (render.time) the count is a bound
    /// and foton's largest stands for it; without one, such a render would not end, and
    /// `--lenient` renders foton's largest count (the TOML reader refuses it as written).
    pub(super) fn samples_past_u32(&mut self) {
        let render = table_mut(&mut self.root, "render");
        let timed = render.get("time").is_some();
        let Some(node) = render.get_mut("spp") else {
            return;
        };
        let Value::Int(spp) = node.value else {
            return;
        };
        if spp <= i64::from(u32::MAX) || !(timed || self.lenient) {
            return;
        }
        node.value = Value::Int(u32::MAX.into());
        if !timed {
            let line = node.line;
            self.report.warnings.push(format!(
                "{}:{line}: `sample_count` = {spp}: more samples than foton counts, rendered with {} (no `timeout` ends the render)",
                self.file.display(),
                u32::MAX
            ));
        }
    }
}
