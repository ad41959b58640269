//! Mitsuba 0.4-0.6 scene files (issue 17): read with Mitsuba 3's upgrade (camelCase names),
//! the old plugins and parameters (ldrfilm, the samplers, media as sigmaS/sigmaA), Mitsuba's
//! integrator names choosing foton's plugins, warnings with file:line that `--strict` turns
//! into errors, and nothing stricter than Mitsuba (lookat without up, include relative to the
//! including file, -D typos, unknown against unsupported elements). The Bitterli scenes in
//! scenes/bitterli are the published files (rendered by every integrator in bitterli.rs).

use foton_loader::image::read_image;
use foton_tests::{Run, foton, foton_with_plugins, repo_root, temp_dir, write};
use std::path::{Path, PathBuf};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn ok(run: &Run) {
    assert_eq!(
        run.code, 0,
        "stdout:\n{}\nstderr:\n{}",
        run.stdout, run.stderr
    );
}

fn failed(run: &Run) -> &str {
    assert_eq!(
        run.code, 1,
        "stdout:\n{}\nstderr:\n{}",
        run.stdout, run.stderr
    );
    &run.stderr
}

/// `foton convert` of `text` written as `dir/name`: the TOML without its header line, and the
/// run (for its warnings).
fn convert(dir: &Path, name: &str, text: &str, extra: &[&str]) -> (String, Run) {
    let xml = write(dir, name, text);
    let toml = dir.join(format!("{name}.toml"));
    let mut args = vec!["convert", s(&xml), "-o", s(&toml)];
    args.extend(extra);
    let run = foton(&args);
    ok(&run);
    let text = std::fs::read_to_string(&toml).unwrap();
    let body = text.lines().skip(1).collect::<Vec<_>>().join("\n");
    (body, run)
}

/// The number after `key = ` on the first line that has it.
fn number(toml: &str, key: &str) -> f64 {
    let line = toml
        .lines()
        .find(|l| l.trim_start().starts_with(&format!("{key} = ")))
        .unwrap_or_else(|| panic!("no {key} in\n{toml}"));
    line.split('=').nth(1).unwrap().trim().parse().unwrap()
}

/// The three numbers of `key = [x, y, z]` (-0 read as 0).
fn vector(toml: &str, key: &str) -> [f64; 3] {
    let line = toml
        .lines()
        .find(|l| l.trim_start().starts_with(&format!("{key} = ")))
        .unwrap_or_else(|| panic!("no {key} in\n{toml}"));
    let inner = line
        .split('[')
        .nth(1)
        .unwrap()
        .trim_end()
        .trim_end_matches(']');
    let v: Vec<f64> = inner
        .split(',')
        .map(|x| x.trim().parse::<f64>().unwrap() + 0.0)
        .collect();
    [v[0], v[1], v[2]]
}

/// A scene in Mitsuba 0.5's words: camelCase names, a medium as sigmaS and sigmaA inside a
/// glass sphere, `fovAxis`, `intIOR`, `toWorld`, `sampleCount`, `maxDepth` and `rrDepth`.
const OLD: &str = r#"<?xml version="1.0"?>
<!-- comments anywhere, attributes in any order -->
<scene version="0.5.0">
    <integrator type="volpath">
        <integer name="maxDepth" value="6"/>
        <integer value="4" name="rrDepth"/>
    </integrator>
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <string name="fovAxis" value="x"/>
        <transform name="toWorld">
            <lookat target="0, 1, 0" origin="0, 1, 4" up="0, 1, 0"/>
        </transform>
        <sampler type="independent"><integer name="sampleCount" value="3"/></sampler>
        <film type="hdrfilm">
            <integer name="width" value="12"/><!-- inside too -->
            <integer name="height" value="10"/>
            <rfilter type="box"/>
        </film>
    </sensor>
    <medium type="homogeneous" id="fog">
        <rgb name="sigmaS" value="0.75, 0.375, 0.375"/>
        <rgb name="sigmaA" value="0.25, 0.125, 0.125"/>
        <float name="scale" value="2"/>
        <phase type="hg"><float name="g" value="0.5"/></phase>
    </medium>
    <bsdf type="dielectric" id="glass">
        <float name="intIOR" value="1.5"/>
        <float name="extIOR" value="1"/>
    </bsdf>
    <shape type="sphere">
        <point name="center" x="0" y="1" z="0"/>
        <float name="radius" value="0.5"/>
        <ref id="glass"/>
        <ref name="interior" id="fog"/>
    </shape>
    <shape type="rectangle">
        <transform name="toWorld"><rotate x="1" angle="90"/><translate y="2"/></transform>
        <bsdf type="diffuse"><rgb name="diffuseReflectance" value="0.2"/></bsdf>
        <emitter type="area"><rgb name="radiance" value="5"/></emitter>
    </shape>
</scene>
"#;

/// The same scene as Mitsuba 3 writes it: sigma_t and albedo (values exact in binary, so that both read alike to the bit).
const NEW: &str = r#"<scene version="3.0.0">
    <integrator type="volpath">
        <integer name="max_depth" value="6"/>
        <integer name="rr_depth" value="4"/>
    </integrator>
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <string name="fov_axis" value="x"/>
        <transform name="to_world">
            <lookat origin="0, 1, 4" target="0, 1, 0" up="0, 1, 0"/>
        </transform>
        <sampler type="independent"><integer name="sample_count" value="3"/></sampler>
        <film type="hdrfilm">
            <integer name="width" value="12"/>
            <integer name="height" value="10"/>
            <rfilter type="box"/>
        </film>
    </sensor>
    <medium type="homogeneous" id="fog">
        <rgb name="sigma_t" value="1, 0.5, 0.5"/>
        <rgb name="albedo" value="0.75"/>
        <float name="scale" value="2"/>
        <phase type="hg"><float name="g" value="0.5"/></phase>
    </medium>
    <bsdf type="dielectric" id="glass">
        <float name="int_ior" value="1.5"/>
        <float name="ext_ior" value="1"/>
    </bsdf>
    <shape type="sphere">
        <point name="center" x="0" y="1" z="0"/>
        <float name="radius" value="0.5"/>
        <ref id="glass"/>
        <ref name="interior" id="fog"/>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><rotate x="1" angle="90"/><translate y="2"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.2"/></bsdf>
        <emitter type="area"><rgb name="radiance" value="5"/></emitter>
    </shape>
</scene>
"#;

/// A Mitsuba 0.5 file reads to the same document as its Mitsuba 3 equivalent (so renders the
/// same image for a seed, bit for bit), the medium's sigmaS and sigmaA kept (Mitsuba 3's
/// upgrade drops them, Mitsuba 0.6 renders them); and the two render the same image.
#[test]
fn an_old_file_reads_as_its_mitsuba_3_equivalent() {
    let (a, b) = (temp_dir("old"), temp_dir("new"));
    let (old, run) = convert(&a, "scene.xml", OLD, &[]);
    assert!(!run.stderr.contains("warning"), "{}", run.stderr);
    let (new, _) = convert(&b, "scene.xml", NEW, &[]);
    assert_eq!(old, new);
    // Mitsuba counts path segments, foton scattering events.
    assert_eq!(number(&old, "max_depth"), 5.0);
    assert_eq!(number(&old, "rr_depth"), 3.0);
    assert!(old.contains("sigma_s = [1.5, 0.75, 0.75]"), "{old}");
    let render = |dir: &Path| {
        let out = dir.join("out.exr");
        ok(&foton_with_plugins(&[
            "render",
            s(&dir.join("scene.xml")),
            "-q",
            "-o",
            s(&out),
        ]));
        read_image(&out).unwrap().2
    };
    let (x, y) = (render(&a), render(&b));
    assert!(x.iter().any(|p| p[0] > 0.0));
    assert_eq!(x, y);
}

fn scene_with(integrator: &str, sensor_extra: &str, film: &str, extra: &str) -> String {
    format!(
        r#"<scene version="0.5.0">
    {integrator}
    <sensor type="perspective">
        <transform name="toWorld"><lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
        {sensor_extra}
        {film}
    </sensor>
    <shape type="rectangle">
        <transform name="toWorld"><scale value="3"/></transform>
        <emitter type="area"><rgb name="radiance" value="1"/></emitter>
    </shape>
    {extra}
</scene>
"#
    )
}

const FILM: &str = r#"<film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film>"#;

/// ldrfilm writes a PNG through foton's exposure; gamma 2.2 is the sRGB curve (a note);
/// Reinhard's tone mapping is a warning naming its line, an error with --strict; the other
/// renamed film parameters are accepted when they ask for what foton writes.
#[test]
fn ldrfilm_is_a_png_with_its_exposure() {
    let dir = temp_dir("ldr");
    let film = r#"<film type="ldrfilm">
            <integer name="width" value="8"/><integer name="height" value="8"/>
            <float name="exposure" value="-1.5"/><float name="gamma" value="2.2"/>
            <string name="fileFormat" value="png"/><string name="pixelFormat" value="rgb"/>
            <boolean name="banner" value="false"/><boolean name="highQualityEdges" value="false"/>
        </film>"#;
    let text = scene_with("", "", film, "");
    let (toml, run) = convert(&dir, "ldr.xml", &text, &[]);
    assert!(toml.contains("output = \"ldr.png\""), "{toml}");
    assert_eq!(number(&toml, "exposure"), -1.5);
    assert!(!run.stderr.contains("warning"), "{}", run.stderr);
    // Rendered: a PNG whose pixels are the radiance 1 times 2^-1.5, sRGB-encoded.
    let xml = dir.join("ldr.xml");
    let run = foton_with_plugins(&["render", s(&xml), "-q", "--spp", "1"]);
    ok(&run);
    let png = image::open(dir.join("ldr.png")).unwrap().to_rgb8();
    let expected = (255.0 * (1.055 * 2f64.powf(-1.5).powf(1.0 / 2.4) - 0.055)).round() as i32;
    let centre = png.get_pixel(4, 4);
    assert!(
        (i32::from(centre[0]) - expected).abs() <= 1,
        "{centre:?} vs {expected}"
    );

    let film = film.replace(
        r#"<float name="gamma" value="2.2"/>"#,
        r#"<string name="tonemapMethod" value="reinhard"/>"#,
    );
    let xml = write(&dir, "reinhard.xml", &scene_with("", "", &film, ""));
    let run = foton_with_plugins(&["check", s(&xml)]);
    ok(&run);
    let line = film_line(&xml, "ldrfilm");
    let place = format!("reinhard.xml:{line}");
    assert!(
        run.stderr.contains(&place) && run.stderr.contains("reinhard"),
        "{}",
        run.stderr
    );
    let run = foton_with_plugins(&["check", s(&xml), "--strict"]);
    let err = failed(&run);
    assert!(err.contains(&place) && err.contains("--strict"), "{err}");
    let run = foton(&["convert", s(&xml), "--strict"]);
    assert!(failed(&run).contains(&place));
}

/// The 1-based line of the first line of `path` containing `what`.
fn film_line(path: &Path, what: &str) -> usize {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .position(|l| l.contains(what))
        .unwrap()
        + 1
}

/// Every sampler Mitsuba has is read: its sample count is the spp; foton's own samplers
/// (independent, stratified, sobol) are taken as they are, the others rendered by the nearest
/// foton has (multijitter by stratified, the low-discrepancy ones by sobol) with a warning
/// naming the sampler and its line, an error with --strict; none is `independent`, Mitsuba's
/// default. An unknown sampler is an error that suggests the close name.
#[test]
fn samplers_map_to_the_nearest_foton_sampler() {
    let dir = temp_dir("samplers");
    for (sampler, foton_sampler) in [
        ("independent", "independent"),
        ("stratified", "stratified"),
        ("sobol", "sobol"),
        ("multijitter", "stratified"),
        ("orthogonal", "sobol"),
        ("ldsampler", "sobol"),
        ("halton", "sobol"),
        ("hammersley", "sobol"),
    ] {
        let s_ = format!(
            r#"<sampler type="{sampler}"><integer name="sampleCount" value="7"/><integer name="scramble" value="2"/></sampler>"#
        );
        let text = scene_with("", &s_, FILM, "");
        let (toml, run) = convert(&dir, &format!("{sampler}.xml"), &text, &[]);
        assert_eq!(number(&toml, "spp"), 7.0);
        assert!(
            toml.contains(&format!("sampler = \"{foton_sampler}\"")),
            "{sampler}: {toml}"
        );
        let exact = sampler == foton_sampler;
        let warned = run.stderr.contains(&format!("{sampler}.xml:5:"))
            && run.stderr.contains(&format!("`{sampler}`"));
        assert_eq!(warned, !exact, "{sampler}: {}", run.stderr);
        let xml = dir.join(format!("{sampler}.xml"));
        let strict = foton(&["convert", s(&xml), "-o", s(&dir.join("x.toml")), "--strict"]);
        assert_eq!(strict.code == 0, exact, "{}", strict.stderr);
    }
    // A file that names no sampler samples independently, as in Mitsuba (foton's own
    // TOML default, sobol, would give the file other noise than Mitsuba's).
    let (toml, _) = convert(&dir, "none.xml", &scene_with("", "", FILM, ""), &[]);
    assert!(toml.contains("sampler = \"independent\""), "{toml}");
    // A stratified sampler's jitter is foton's.
    let s_ = r#"<sampler type="stratified"><integer name="sampleCount" value="4"/><boolean name="jitter" value="false"/></sampler>"#;
    let (toml, _) = convert(&dir, "centred.xml", &scene_with("", s_, FILM, ""), &[]);
    assert!(toml.contains("jitter = false"), "{toml}");
    let text = scene_with("", r#"<sampler type="sobel"/>"#, FILM, "");
    let xml = write(&dir, "typo.xml", &text);
    let err = foton(&["convert", s(&xml)]);
    assert!(
        failed(&err).contains("did you mean `sobol`"),
        "{}",
        err.stderr
    );
}

/// Mitsuba's integrator names choose foton's plugins with their parameters translated, and
/// `foton check` says what renders (the plugin with its parameters).
#[test]
fn mitsuba_integrators_choose_foton_plugins() {
    let dir = temp_dir("integrators");
    let fog = r#"<medium type="homogeneous" id="fog"><rgb name="sigmaS" value="0.1"/><rgb name="sigmaA" value="0"/></medium>
    <shape type="sphere"><float name="radius" value="0.5"/><bsdf type="null"/><ref name="interior" id="fog"/></shape>"#;
    // The integrator element, what else the scene holds, the values expected, the plugin.
    type Case<'a> = (&'a str, &'a str, &'a [(&'a str, f64)], &'a str);
    let cases: &[Case] = &[
        (
            r#"<integrator type="photonmapper"><integer name="globalPhotons" value="1000"/><integer name="causticPhotons" value="500"/><integer name="lookupSize" value="20"/><integer name="maxDepth" value="-1"/></integrator>"#,
            "",
            &[
                ("global_photons", 1000.0),
                ("caustic_photons", 500.0),
                ("k", 20.0),
                ("max_depth", 65536.0),
            ],
            "photon",
        ),
        (
            r#"<integrator type="photonmapper"><integer name="volumePhotons" value="300"/><integer name="globalPhotons" value="1000"/><integer name="causticPhotons" value="500"/><integer name="lookupSize" value="20"/></integrator>"#,
            fog,
            &[
                ("volume_photons", 300.0),
                ("k_volume", 20.0),
                ("global_photons", 1000.0),
            ],
            "vpm",
        ),
        (
            r#"<integrator type="sppm"><integer name="photonCount" value="5000"/><float name="initialRadius" value="0.1"/><float name="alpha" value="0.5"/><integer name="maxPasses" value="3"/></integrator>"#,
            "",
            &[
                ("photons_per_iteration", 5000.0),
                ("initial_radius", 0.1),
                ("alpha", 0.5),
                ("iterations", 3.0),
            ],
            "sppm",
        ),
        (
            r#"<integrator type="ppm"><integer name="photonCount" value="5000"/><integer name="passes" value="2"/></integrator>"#,
            "",
            &[("photons_per_iteration", 5000.0), ("iterations", 2.0)],
            "sppm",
        ),
        (
            r#"<integrator type="volpath_simple"><integer name="maxDepth" value="3"/></integrator>"#,
            fog,
            // Mitsuba starts Russian roulette at depth 5 when the file does not say.
            &[("max_depth", 2.0), ("rr_depth", 4.0)],
            "path",
        ),
        (
            r#"<integrator type="bdpt"><integer name="maxDepth" value="8"/><integer name="rrDepth" value="6"/><boolean name="lightImage" value="false"/></integrator>"#,
            "",
            &[("max_depth", 7.0), ("rr_depth", 5.0)],
            "bdpt",
        ),
    ];
    for (i, (integrator, extra, values, plugin)) in cases.iter().enumerate() {
        let text = scene_with(
            integrator,
            r#"<sampler type="independent"><integer name="sampleCount" value="1"/></sampler>"#,
            FILM,
            extra,
        );
        let (toml, _) = convert(&dir, &format!("case{i}.xml"), &text, &[]);
        assert!(
            toml.contains(&format!("integrator = \"{plugin}\"")),
            "{toml}"
        );
        for (key, value) in *values {
            assert_eq!(number(&toml, key), *value, "{key} in\n{toml}");
        }
        if *plugin == "bdpt" {
            // lightImage = false: bdpt without its light-tracing strategies.
            assert!(toml.contains("light_image = false"), "{toml}");
        }
        let run = foton_with_plugins(&["check", s(&dir.join(format!("case{i}.xml")))]);
        ok(&run);
        assert!(
            run.stdout.contains(&format!("integrator {plugin}")),
            "{}",
            run.stdout
        );
    }
    // The lookup radius is relative to the bounding sphere: the emitter is [-3, 3]^2, whose
    // bounding sphere has radius 3 sqrt(2); Mitsuba's default fraction is 0.05.
    let (toml, _) = convert(
        &dir,
        "case0-radius.xml",
        &scene_with(cases[0].0, "", FILM, ""),
        &[],
    );
    let r = number(&toml, "max_radius");
    // (The bounds are single precision, padded a little.)
    assert!((r / (0.05 * 3.0 * 2f64.sqrt()) - 1.0).abs() < 1e-4, "{r}");
    // Parameters without an equivalent are warnings naming them.
    let pm = r#"<integrator type="photonmapper"><integer name="directSamples" value="4"/><float name="causticLookupRadius" value="0.01"/></integrator>"#;
    let (_, run) = convert(&dir, "warn.xml", &scene_with(pm, "", FILM, ""), &[]);
    for name in ["direct_samples", "caustic_lookup_radius"] {
        assert!(
            run.stderr.contains(&format!(
                "warn.xml:2: <integrator type=\"photonmapper\">: `{name}`"
            )),
            "{}",
            run.stderr
        );
    }
    // `--integrator` still overrides the file.
    let run = foton_with_plugins(&["check", s(&dir.join("case0.xml")), "--integrator", "path"]);
    ok(&run);
    assert!(run.stdout.contains("integrator path"), "{}", run.stdout);
    // Known but not rendered, and unknown with a suggestion.
    for (ty, says) in [
        ("ao", "is not supported"),
        ("phtonmapper", "did you mean `photonmapper`"),
    ] {
        let text = scene_with(&format!(r#"<integrator type="{ty}"/>"#), "", FILM, "");
        let xml = write(&dir, &format!("{ty}.xml"), &text);
        let run = foton(&["convert", s(&xml)]);
        assert!(failed(&run).contains(says), "{}", run.stderr);
    }
}

/// `<lookat>` without `up` takes Mitsuba's: the first vector of its coordinate_system of the
/// viewing direction, here (1, 0, 0) for a camera looking down -z.
#[test]
fn lookat_without_up_is_mitsubas() {
    let dir = temp_dir("lookat");
    let with = scene_with("", "", FILM, "");
    let without = with.replace(r#" up="0, 1, 0""#, "");
    let explicit = with.replace(r#"up="0, 1, 0""#, r#"up="1, 0, 0""#);
    let (a, _) = convert(&dir, "a.xml", &without, &[]);
    let (b, _) = convert(&dir, "b.xml", &explicit, &[]);
    assert_eq!(vector(&a, "up"), [1.0, 0.0, 0.0], "{a}");
    assert_eq!(vector(&a, "up"), vector(&b, "up"));
    assert_eq!(vector(&a, "look_at"), vector(&b, "look_at"));
}

/// An `<include>` is found relative to the file that includes it, at every level.
#[test]
fn include_is_relative_to_the_including_file() {
    let dir = temp_dir("include");
    std::fs::create_dir_all(dir.join("parts/deeper")).unwrap();
    write(
        &dir.join("parts"),
        "lights.xml",
        r#"<scene version="0.5.0"><include filename="deeper/light.xml"/></scene>"#,
    );
    write(
        &dir.join("parts/deeper"),
        "light.xml",
        r#"<scene version="0.5.0"><emitter type="point"><point name="position" x="0" y="0" z="2"/></emitter></scene>"#,
    );
    let text = scene_with("", "", FILM, r#"<include filename="parts/lights.xml"/>"#);
    let (toml, _) = convert(&dir, "main.xml", &text, &[]);
    assert!(toml.contains("type = \"point\""), "{toml}");
}

/// Errors: an XML error calls itself one (never TOML); a `-D` the file never uses is an error
/// that suggests the close one; an unknown element is "unknown" with a suggestion, a Mitsuba
/// element foton does not read "not supported".
#[test]
fn xml_errors_say_what_and_where() {
    let dir = temp_dir("xml-errors");
    let xml = write(
        &dir,
        "broken.xml",
        "<scene version=\"0.5.0\">\n<shape type=\"sphere\">\n</scene>\n",
    );
    let run = foton(&["check", s(&xml)]);
    let err = failed(&run);
    assert!(
        err.contains("broken.xml:3") && err.contains("XML error"),
        "{err}"
    );
    assert!(!err.contains("TOML"), "{err}");

    let text = scene_with(
        "",
        r#"<sampler type="independent"><integer name="sampleCount" value="$spp"/></sampler>"#,
        FILM,
        "",
    )
    .replace(
        "<scene version=\"0.5.0\">",
        "<scene version=\"0.5.0\">\n<default name=\"spp\" value=\"2\"/>",
    );
    let xml = write(&dir, "defines.xml", &text);
    ok(&foton(&["convert", s(&xml), "-D", "spp=3"]));
    let run = foton(&["convert", s(&xml), "-D", "sp=3"]);
    assert!(
        failed(&run).contains("-D sp") && run.stderr.contains("did you mean `spp`"),
        "{}",
        run.stderr
    );

    for (element, says) in [
        (
            r#"<flaot name="x" value="1"/>"#,
            "unknown element <flaot> in <shape> (did you mean `float`?)",
        ),
        (
            r#"<animation name="x"/>"#,
            "<animation> in <shape> is not supported",
        ),
    ] {
        let text = scene_with(
            "",
            "",
            FILM,
            &format!(r#"<shape type="sphere">{element}</shape>"#),
        );
        let xml = write(&dir, "element.xml", &text);
        let run = foton(&["convert", s(&xml)]);
        assert!(failed(&run).contains(says), "{}", run.stderr);
    }
    let text = scene_with("", "", FILM, "").replace("0.5.0", "9.0.0");
    let xml = write(&dir, "version.xml", &text);
    let run = foton(&["convert", s(&xml)]);
    assert!(
        failed(&run).contains("expected a Mitsuba version"),
        "{}",
        run.stderr
    );
}

fn bitterli(scene: &str) -> PathBuf {
    repo_root().join("scenes/bitterli").join(scene)
}

/// Bitterli's volumetric caustic (fog on both sides of its walls, a front without a BSDF:
/// media as Mitsuba 0.6 writes them) loads; what it asks for that foton ignores is a warning
/// with its line, and the front is Mitsuba 0.6's null boundary.
#[test]
fn bitterli_volumetric_caustic_reads_as_mitsuba_0_6_does() {
    let run = foton_with_plugins(&["check", s(&bitterli("volumetric-caustic/scene_v0.6.xml"))]);
    ok(&run);
    assert!(
        run.stderr.contains("scene_v0.6.xml:6:") && run.stderr.contains("strict_normals"),
        "{}",
        run.stderr
    );
    assert!(run.stdout.contains("null_boundary"), "{}", run.stdout);
}

/// scenes/bitterli is the published files unchanged: the same bytes as in
/// `../shared/scenes/bitterli` (beside the repository in CI, which sets FOTON_REQUIRE_SHARED
/// so that its absence fails there; a clone elsewhere says that it skips).
#[test]
fn bitterli_scenes_are_the_published_files() {
    let shared = repo_root().join("../shared/scenes/bitterli");
    if !shared.join("veach-bidir").exists() {
        assert!(
            std::env::var_os("FOTON_REQUIRE_SHARED").is_none(),
            "{} is missing",
            shared.display()
        );
        eprintln!("skipped: {} is not beside this clone", shared.display());
        return;
    }
    let mut compared = 0;
    let mut folders = vec![
        PathBuf::from("veach-bidir"),
        PathBuf::from("volumetric-caustic"),
    ];
    while let Some(folder) = folders.pop() {
        for entry in std::fs::read_dir(shared.join(&folder)).unwrap() {
            let rel = folder.join(entry.unwrap().file_name());
            if shared.join(&rel).is_dir() {
                folders.push(rel);
                continue;
            }
            let ours = std::fs::read(bitterli(s(&rel)))
                .unwrap_or_else(|e| panic!("{}: {e}", rel.display()));
            assert!(
                ours == std::fs::read(shared.join(&rel)).unwrap(),
                "{} differs",
                rel.display()
            );
            compared += 1;
        }
    }
    assert!(compared >= 16, "{compared}");
}

/// A plugin type Mitsuba has and foton does not read is "not supported"; one Mitsuba does not
/// have either is "unknown", with the close name.
#[test]
fn unknown_plugin_types_suggest_the_close_one() {
    let dir = temp_dir("plugin-types");
    for (element, says) in [
        (
            r#"<shape type="sphere"><bsdf type="difuse"/></shape>"#,
            "unknown bsdf type `difuse` (did you mean `diffuse`?)",
        ),
        (
            r#"<shape type="sphere"><bsdf type="irawan"/></shape>"#,
            "this BSDF is not supported yet",
        ),
        (
            r#"<shape type="spheer"/>"#,
            "unknown shape type `spheer` (did you mean `sphere`?)",
        ),
        (
            r#"<emitter type="directionalarea"/>"#,
            "this emitter is not supported yet",
        ),
    ] {
        let xml = write(&dir, "types.xml", &scene_with("", "", FILM, element));
        let run = foton(&["convert", s(&xml)]);
        assert!(failed(&run).contains(says), "{}", run.stderr);
    }
}

/// The 0.6 forms of a medium, colours and parameters, each as Mitsuba 0.6 means it: a
/// medium as sigmaT and albedo with densityMultiplier, Henyey-Greenstein's default g (0 in
/// 0.6, for a medium Mitsuba 3 refuses; one of sigmaT and albedo alone, which Mitsuba 3 reads,
/// takes its default, 0.8, as Mitsuba 3.9.1 loading such a 0.6.0 file does), `<srgb>` colours (sRGB-decoded), a conductor's extEta, a texture's uscale and
/// uoffset (a to_uv transform), hdrfilm's componentFormat float16 (a warning: foton writes
/// 32-bit floats), and a medium given both ways (an error).
#[test]
fn old_media_colours_and_parameters() {
    let dir = temp_dir("old-params");
    let extra = r##"<medium type="homogeneous" id="fog">
        <rgb name="sigmaT" value="2"/><rgb name="albedo" value="0.5"/>
        <float name="densityMultiplier" value="0.5"/><phase type="hg"/>
    </medium>
    <medium type="homogeneous" id="haze">
        <rgb name="sigmaS" value="1"/><rgb name="sigmaA" value="0"/><phase type="isotropic"/>
    </medium>
    <medium type="homogeneous" id="mist">
        <rgb name="sigmaT" value="2"/><rgb name="albedo" value="0.5"/><phase type="hg"/>
    </medium>
    <shape type="sphere"><point name="center" x="-3" y="0" z="0"/><bsdf type="null"/><ref name="interior" id="mist"/></shape>
    <shape type="sphere"><bsdf type="null"/><ref name="interior" id="fog"/></shape>
    <shape type="sphere"><point name="center" x="3" y="0" z="0"/><bsdf type="null"/><ref name="interior" id="haze"/></shape>
    <shape type="sphere"><point name="center" x="0" y="3" z="0"/>
        <bsdf type="diffuse"><srgb name="reflectance" value="#ff8000"/></bsdf></shape>
    <shape type="sphere"><point name="center" x="0" y="-3" z="0"/>
        <bsdf type="conductor"><rgb name="eta" value="2, 3, 4"/><rgb name="k" value="4"/><float name="extEta" value="2"/></bsdf></shape>
    <shape type="sphere"><point name="center" x="3" y="3" z="0"/>
        <bsdf type="diffuse"><texture type="checkerboard" name="reflectance">
            <float name="uscale" value="4"/><float name="voffset" value="0.5"/>
        </texture></bsdf></shape>"##;
    let film = r#"<film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/><string name="componentFormat" value="float16"/></film>"#;
    let (toml, run) = convert(&dir, "old.xml", &scene_with("", "", film, extra), &[]);
    assert!(
        run.stderr.contains("old.xml:6:")
            && run.stderr.contains("`component_format` = \"float16\""),
        "{}",
        run.stderr
    );
    let table = |name: &str| {
        let start = toml.find(&format!("[media.{name}]")).unwrap();
        toml[start..]
            .split("\n\n")
            .take(2)
            .collect::<Vec<_>>()
            .join("\n")
    };
    let fog = table("fog");
    assert_eq!(vector(&fog, "sigma_s"), [0.5, 0.5, 0.5], "{fog}");
    assert_eq!(vector(&fog, "sigma_a"), [0.5, 0.5, 0.5], "{fog}");
    assert_eq!(number(&fog, "g"), 0.0, "{fog}");
    let mist = table("mist");
    assert_eq!(number(&mist, "g"), 0.8, "{mist}");
    assert!(table("haze").contains("phase = \"isotropic\""), "{toml}");
    let orange = vector(&toml, "reflectance");
    assert_eq!(orange[0], 1.0);
    assert!(
        (orange[1] - 0.2158605).abs() < 1e-6 && orange[2] == 0.0,
        "{orange:?}"
    );
    assert_eq!(vector(&toml, "eta"), [1.0, 1.5, 2.0]);
    assert_eq!(vector(&toml, "k"), [2.0, 2.0, 2.0]);
    // to_uv = scale(4, 1) translate(0, 0.5): row-major [4, 0, 0, 0, 0, 1, 0, 0.5, ...].
    let to_uv = &toml[toml.find("to_uv]").unwrap()..];
    let to_uv = to_uv.lines().find(|l| l.starts_with("matrix")).unwrap();
    assert!(
        to_uv.contains("matrix = [4.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.5,"),
        "{to_uv}"
    );

    let both = extra.replace(
        r#"<rgb name="albedo" value="0.5"/>"#,
        r#"<rgb name="sigmaS" value="0.5"/>"#,
    );
    let xml = write(&dir, "both.xml", &scene_with("", "", FILM, &both));
    let run = foton(&["convert", s(&xml)]);
    assert!(failed(&run).contains("not both"), "{}", run.stderr);
}

/// Mitsuba 0.6's `conductor` of `material` "none" (a perfect mirror) with an `extEta`
/// (a name or a number): read, and still a perfect mirror (its eta is 0, so eta / ext is).
#[test]
fn a_mirror_conductor_takes_an_exterior_index() {
    let dir = temp_dir("none-ext-eta");
    let extra = r#"<shape type="sphere"><bsdf type="conductor"><string name="material" value="none"/>
        <string name="extEta" value="air"/></bsdf></shape>"#;
    let (toml, run) = convert(&dir, "mirror.xml", &scene_with("", "", FILM, extra), &[]);
    ok(&run);
    assert!(toml.contains("material = \"none\""), "{toml}");
    let bad = r#"<shape type="sphere"><bsdf type="conductor"><string name="material" value="none"/>
        <string name="extEta" value="unobtainium"/></bsdf></shape>"#;
    let xml = write(&dir, "bad.xml", &scene_with("", "", FILM, bad));
    let run = foton(&["convert", s(&xml)]);
    assert!(failed(&run).contains("unobtainium"), "{}", run.stderr);
}
