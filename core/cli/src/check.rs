//! `foton check`: loads a scene and creates its integrator without rendering, and lists what
//! the scene holds (the integrator's parameters, materials, media, shapes, lights).

use crate::common::{SceneArgs, warn};
use clap::Args;
use foton_core::error::Result;
use foton_core::light::LIGHTS;
use foton_core::registry;
use std::io::Write;

#[derive(Args)]
pub(crate) struct CheckArgs {
    #[command(flatten)]
    scene: SceneArgs,
}

pub(crate) fn run(a: CheckArgs, out: &mut dyn Write, err: &mut dyn Write) -> Result<u8> {
    let p = a.scene.prepare(&a.scene.overrides())?;
    let s = &p.scene;
    let _ = writeln!(out, "scene      {}", s.file().display());
    let _ = writeln!(out, "integrator {}", p.integrator.describe());
    let _ = writeln!(
        out,
        "render     {}x{}, {} spp ({}), seed {}, max_depth {} -> {}",
        s.film().width,
        s.film().height,
        s.render().spp,
        s.render().sampler.name(),
        s.render().seed,
        s.render().max_depth,
        s.film().output.display()
    );
    let names = |v: Vec<&str>| {
        if v.is_empty() {
            "-".to_string()
        } else {
            v.join(", ")
        }
    };
    let _ = writeln!(
        out,
        "materials  {}",
        names(s.materials().iter().map(|m| m.name.as_str()).collect())
    );
    let _ = writeln!(
        out,
        "media      {}",
        names(s.media().iter().map(|m| m.name.as_str()).collect())
    );
    let _ = writeln!(
        out,
        "shapes     {} ({} primitives)",
        s.objects().len(),
        s.accel().primitives().len()
    );
    // By kind, in the order of the light table; points and areas even when there are none.
    let listed: Vec<String> = registry::names(LIGHTS)
        .map(|kind| (kind, s.lights().iter().filter(|l| l.name() == kind).count()))
        .filter(|&(kind, n)| n > 0 || matches!(kind, "point" | "area"))
        .map(|(kind, n)| format!("{n} {kind}"))
        .collect();
    let power = s.total_power();
    let _ = writeln!(
        out,
        "lights     {}; total power [{:.4}, {:.4}, {:.4}] W",
        listed.join(", "),
        power.x,
        power.y,
        power.z
    );
    warn(err, &p.warnings);
    let _ = writeln!(out, "ok");
    Ok(0)
}
