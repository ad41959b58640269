//! Meters as the sensor (TOML `[camera] type = "radiancemeter"` and `"irradiancemeter"` with
//! the shapes marked `sensor = true`, Mitsuba's `radiancemeter` and the `irradiancemeter`
//! nested in a shape): one value, measured by the path tracer against what physics says it
//! is. An irradiance meter records pi L inside a uniform environment and pi L F between two
//! discs (F their form factor); a radiance meter looking through an absorber records
//! L exp(-sigma_a d). Integrators that cannot reach a meter refuse it; the readers read the
//! meters as Mitsuba 0.6 and 3 do.

use foton_core::film::Film;
use foton_tests::{foton_with_plugins, header, render_file, render_toml, temp_dir, write};

/// The standard error of the mean of `n` samples that are `value` with probability `p` and
/// 0 otherwise.
fn bernoulli_se(value: f64, p: f64, n: u32) -> f64 {
    value * (p * (1.0 - p) / f64::from(n)).sqrt()
}

fn value(film: &Film) -> [f64; 3] {
    assert_eq!((film.width, film.height), (1, 1));
    let p = film.pixel(0, 0);
    [f64::from(p.x), f64::from(p.y), f64::from(p.z)]
}

/// Two coaxial black discs of radius 1, `gap` apart: the lower one the meter's surface, the
/// upper one emitting radiance 1 downwards.
fn discs(spp: u32, gap: f64) -> String {
    header("path", spp, 8, 1, 1)
        + &format!(
            r#"
[film.filter]
type = "box"

[camera]
type = "irradiancemeter"

[materials.black]
type = "diffuse"
reflectance = [0.0, 0.0, 0.0]

[[shapes]]
type = "disk"
center = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
radius = 1.0
material = "black"
sensor = true

[[shapes]]
type = "disk"
center = [0.0, 0.0, {gap}]
normal = [0.0, 0.0, -1.0]
radius = 1.0
material = "black"
emission = [1.0, 1.0, 1.0]
"#
        )
}

/// The form factor between two coaxial discs of radius 1 a distance `h` apart.
fn disc_form_factor(h: f64) -> f64 {
    let x = 2.0 + h * h;
    (x - (x * x - 4.0).sqrt()) / 2.0
}

/// Each sample of the meter is pi (a cosine-weighted direction that reaches the emitter) or 0:
/// the mean is pi F, within its binomial error.
#[test]
fn an_irradiance_meter_records_pi_times_the_form_factor_between_discs() {
    let spp = 400_000;
    for gap in [0.5, 2.0] {
        let film = render_toml("meter-discs", &discs(spp, gap), &[], 2);
        let f = disc_form_factor(gap);
        let expected = std::f64::consts::PI * f;
        let se = bernoulli_se(std::f64::consts::PI, f, spp);
        for c in value(&film) {
            assert!(
                (c - expected).abs() < 4.5 * se,
                "gap {gap}: {c} against pi F = {expected} (se {se})"
            );
        }
    }
}

/// A black sphere in an environment of radiance L: every direction of the hemisphere above
/// every point sees L, so every sample is exactly pi L (Mitsuba's normalisation: an irradiance
/// meter inside an integrating sphere of radiance 1 records pi).
#[test]
fn an_irradiance_meter_in_a_uniform_environment_records_pi_l() {
    let scene = header("path", 64, 4, 1, 1)
        + r#"
[film.filter]
type = "box"

[camera]
type = "irradiancemeter"

[materials.black]
type = "diffuse"
reflectance = [0.0, 0.0, 0.0]

[[shapes]]
type = "sphere"
center = [0.3, -0.2, 1.0]
radius = 0.7
material = "black"
sensor = true

[[lights]]
type = "constant"
radiance = [0.5, 1.0, 2.0]
"#;
    let film = render_toml("meter-sphere", &scene, &[], 2);
    let got = value(&film);
    for (c, l) in got.iter().zip([0.5, 1.0, 2.0]) {
        let expected = std::f64::consts::PI * l;
        assert!(
            (c - expected).abs() < 1e-4 * expected,
            "{got:?} against pi L = {expected}"
        );
    }
}

/// A radiance meter looks through a purely absorbing medium at an emitting quad `d` away:
/// the radiance that arrives is L exp(-sigma_a d) (each sample passes or not: a binomial error).
#[test]
fn a_radiance_meter_through_an_absorber_records_l_exp_minus_sigma_d() {
    let (sigma, d, spp): (f64, f64, u32) = (0.8, 1.5, 100_000);
    let scene = header("path", spp, 4, 1, 1)
        + &format!(
            r#"
[film.filter]
type = "box"

[camera]
type = "radiancemeter"
position = [0.0, 0.0, 0.0]
look_at = [0.0, 0.0, -1.0]

[scene]
medium = "absorber"

[media.absorber]
type = "homogeneous"
sigma_a = [{sigma}, {sigma}, {sigma}]

[materials.black]
type = "diffuse"
reflectance = [0.0, 0.0, 0.0]

[[shapes]]
type = "quad"
origin = [-1.0, -1.0, -{d}]
u = [2.0, 0.0, 0.0]
v = [0.0, 2.0, 0.0]
material = "black"
emission = [2.0, 2.0, 2.0]
"#
        );
    let film = render_toml("meter-absorber", &scene, &[], 2);
    let t = (-sigma * d).exp();
    let expected = 2.0 * t;
    // At most the error of a binomial estimate of T; an analytic transmittance has none.
    let se = bernoulli_se(2.0, t, spp);
    for c in value(&film) {
        assert!(
            (c - expected).abs() < 4.5 * se + 1e-6,
            "{c} against L exp(-sigma d) = {expected}"
        );
    }
}

/// An integrator that does not trace paths from the camera cannot reach a meter: it refuses
/// the scene with a message that names the one that can.
#[test]
fn integrators_that_cannot_reach_a_meter_refuse_it() {
    let dir = temp_dir("meter-refused");
    let scene = write(&dir, "scene.toml", &discs(16, 1.0));
    for integrator in ["bdpt", "sppm"] {
        let run = foton_with_plugins(&[
            "render",
            scene.to_str().unwrap(),
            "-q",
            "--integrator",
            integrator,
        ]);
        assert_ne!(run.code, 0, "{integrator}: {}", run.stderr);
        assert!(
            run.stderr.contains("meter") && run.stderr.contains("`path`"),
            "{integrator}: {}",
            run.stderr
        );
    }
}

/// What a meter needs, each missing one an error at its field.
#[test]
fn meters_refuse_what_they_cannot_measure() {
    let dir = temp_dir("meter-bad");
    let cases: [(String, &str); 5] = [
        (
            discs(4, 1.0).replace("width = 1", "width = 2"),
            "film must be 1x1",
        ),
        (
            discs(4, 1.0).replace("type = \"box\"", "type = \"gaussian\""),
            "box filter",
        ),
        (discs(4, 1.0).replace("sensor = true", ""), "none is"),
        (
            discs(4, 1.0).replace(
                "type = \"irradiancemeter\"",
                "type = \"perspective\"\nposition = [0.0, 0.0, 5.0]\nlook_at = [0.0, 0.0, 0.0]",
            ),
            "is not one",
        ),
        (
            discs(4, 1.0).replace(
                "type = \"irradiancemeter\"",
                "type = \"irradiancemeter\"\nposition = [0.0, 0.0, 5.0]",
            ),
            "has no meaning for an irradiancemeter",
        ),
    ];
    for (i, (scene, needle)) in cases.iter().enumerate() {
        let path = write(&dir, &format!("bad{i}.toml"), scene);
        let run = foton_with_plugins(&["check", path.to_str().unwrap()]);
        assert_ne!(run.code, 0, "case {i}");
        assert!(
            run.stderr.contains(needle) && run.stderr.contains(&format!("bad{i}.toml:")),
            "case {i}: {}",
            run.stderr
        );
    }
}

/// Mitsuba 0.6's test of its particle tracer (data/tests/test_bidir_0.xml, with black discs):
/// an irradiance meter nested in a disc, an mfilm, `ptracer`, rendered by path to pi F.
const MITSUBA06_METER: &str = r#"<scene version="0.5.0">
	<integrator type="ptracer"/>
	<shape type="disk">
		<transform name="toWorld"><translate z="-1"/></transform>
		<bsdf type="diffuse"><spectrum name="reflectance" value="0"/></bsdf>
		<sensor type="irradiancemeter">
			<sampler type="independent"><integer name="sampleCount" value="400000"/></sampler>
			<film type="mfilm"/>
		</sensor>
	</shape>
	<shape type="disk">
		<boolean name="flipNormals" value="true"/>
		<bsdf type="diffuse"><spectrum name="reflectance" value="0"/></bsdf>
		<transform name="toWorld"><translate z="1"/></transform>
		<emitter type="area"><rgb name="radiance" value="1"/></emitter>
	</shape>
</scene>
"#;

#[test]
fn mitsuba_irradiance_meters_nested_in_a_shape_measure_its_surface() {
    let dir = temp_dir("meter-mitsuba06");
    let xml = write(&dir, "meter.xml", MITSUBA06_METER);
    let run = foton_with_plugins(&["check", xml.to_str().unwrap()]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(
        run.stderr.contains("rendered by path") && run.stderr.contains("mfilm"),
        "{}",
        run.stderr
    );
    // Rendered strictly (a warning is an error): the same meter on a 1 x 1 hdrfilm.
    let hdr = MITSUBA06_METER.replace(
        "<film type=\"mfilm\"/>",
        "<film type=\"hdrfilm\"><integer name=\"width\" value=\"1\"/><integer name=\"height\" value=\"1\"/></film>",
    );
    let film = render_file(&write(&dir, "hdr.xml", &hdr), &[], 2);
    let f = disc_form_factor(2.0);
    let expected = std::f64::consts::PI * f;
    let se = bernoulli_se(std::f64::consts::PI, f, 400_000);
    for c in value(&film) {
        assert!((c - expected).abs() < 4.5 * se, "{c} against {expected}");
    }
    // Alone, an irradiance meter has no surface; Mitsuba 3 takes only a 1 x 1 film.
    let alone = write(
        &dir,
        "alone.xml",
        "<scene version=\"3.0.0\"><sensor type=\"irradiancemeter\"/><shape type=\"sphere\"/></scene>",
    );
    let run = foton_with_plugins(&["check", alone.to_str().unwrap()]);
    assert!(
        run.code != 0 && run.stderr.contains("alone.xml:1") && run.stderr.contains("nested"),
        "{}",
        run.stderr
    );
    let big = MITSUBA06_METER
        .replace("0.5.0", "3.0.0")
        .replace("toWorld", "to_world")
        .replace("flipNormals", "flip_normals")
        .replace("sampleCount", "sample_count")
        .replace("<integrator type=\"ptracer\"/>", "")
        .replace("<film type=\"mfilm\"/>", "<film type=\"hdrfilm\"/>");
    let big = write(&dir, "big.xml", &big);
    let run = foton_with_plugins(&["check", big.to_str().unwrap()]);
    assert!(
        run.code != 0 && run.stderr.contains("768 x 576"),
        "{}",
        run.stderr
    );
}

/// Mitsuba 3's radiance meter at `origin` looking along `direction` at an emitter of radiance
/// 3 records 3, whatever the integrator the file names (path renders it); with `to_world` as
/// well, Mitsuba 3 refuses the file, and so does foton.
#[test]
fn mitsuba_radiance_meters_look_along_their_direction() {
    let dir = temp_dir("meter-mitsuba3");
    let body = |sensor_extra: &str| {
        format!(
            r#"<scene version="3.0.0">
    <integrator type="bdpt"/>
    <sensor type="radiancemeter">
        <point name="origin" x="0" y="0" z="0"/>
        <vector name="direction" x="1" y="0" z="0"/>
        {sensor_extra}
        <film type="hdrfilm"><integer name="width" value="1"/><integer name="height" value="1"/></film>
        <sampler type="independent"><integer name="sample_count" value="16"/></sampler>
    </sensor>
    <shape type="rectangle">
        <transform name="to_world"><rotate y="1" angle="-90"/><translate x="2"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf>
        <emitter type="area"><rgb name="radiance" value="3"/></emitter>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><rotate y="1" angle="90"/><translate x="-2"/></transform>
        <emitter type="area"><rgb name="radiance" value="1"/></emitter>
    </shape>
</scene>
"#
        )
    };
    let xml = write(&dir, "radiance.xml", &body(""));
    let film = render_file(&xml, &[], 2);
    for c in value(&film) {
        assert!((c - 3.0).abs() < 1e-5, "{c} against the radiance 3 ahead");
    }
    let both = write(
        &dir,
        "both.xml",
        &body("<transform name=\"to_world\"><translate x=\"1\"/></transform>"),
    );
    let run = foton_with_plugins(&["check", both.to_str().unwrap()]);
    assert!(
        run.code != 0 && run.stderr.contains("not both"),
        "{}",
        run.stderr
    );
}
