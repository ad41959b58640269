//! Spectra in Mitsuba scene files, reduced to RGB as Mitsuba 3's RGB variants reduce them in
//! files of every version (issue 32): wavelength:value pairs and `.spd` files (reflectances
//! under D65 and clamped, emission unweighted), a flat emission's colour; the forms only
//! Mitsuba 0.6 reads (three values as r, g, b in files older than 2.0, `#rrggbb`), blackbodies, the named conductors' measured
//! indices, and the errors of malformed spectra.
//!
//! The reference values are Mitsuba 3.9.1's (`pip install mitsuba`, variant `scalar_rgb`),
//! read back with `mi.traverse` after `mi.load_string` of a scene holding the spectrum, e.g.
//!
//! ```text
//! import mitsuba as mi; mi.set_variant('scalar_rgb')
//! s = mi.load_string('<scene version="3.0.0"><shape type="sphere"><bsdf type="diffuse">'
//!     '<spectrum name="reflectance" value="400:0.1, 500:0.5, 600:0.8, 700:0.3"/>'
//!     '</bsdf></shape></scene>')
//! print(mi.traverse(s))   # ...bsdf.reflectance.value [0.752187, 0.645269, 0.271706]
//! ```
//!
//! (an `<emitter type="area">` with `<spectrum name="radiance" .../>` for emission, a
//! `<bsdf type="conductor">` for `eta` and `k`).

use foton_core::spectrum::{self, Quantity, Spectrum};
use foton_core::value::{Document, Table, Value};
use foton_loader::mitsuba::read_xml;
use foton_tests::{temp_dir, write};
use glam::DVec3;

/// The scene of one `<bsdf>` (or emitter) `body`, read into foton's document.
fn read(name: &str, version: &str, body: &str) -> Result<Document, String> {
    let dir = temp_dir(&format!("spectra-{name}"));
    let text =
        format!("<scene version=\"{version}\">\n<emitter type=\"constant\"/>\n{body}\n</scene>\n");
    let path = write(&dir, "scene.xml", &text);
    read_xml(&path, &[], false)
        .map(|(d, _)| d)
        .map_err(|e| e.to_string())
}

fn table<'t>(t: &'t Table, key: &str) -> &'t Table {
    match &t.get(key).unwrap_or_else(|| panic!("no {key}")).value {
        Value::Table(t) => t,
        other => panic!("{key}: {other:?}"),
    }
}

fn rgb(t: &Table, key: &str) -> DVec3 {
    let Value::Array(a) = &t.get(key).unwrap_or_else(|| panic!("no {key}")).value else {
        panic!("{key}: {:?}", t.get(key))
    };
    let x: Vec<f64> = a.iter().map(|n| n.value.as_f64().unwrap()).collect();
    DVec3::new(x[0], x[1], x[2])
}

/// The first material's parameter `key`.
fn material(doc: &Document, key: &str) -> DVec3 {
    let materials = table(&doc.root, "materials");
    let (_, first) = materials.0.first().expect("a material");
    let Value::Table(m) = &first.value else {
        panic!("{first:?}")
    };
    rgb(m, key)
}

/// The colour a diffuse BSDF's reflectance written as `spectrum` reads as.
fn reflectance(version: &str, spectrum: &str) -> DVec3 {
    let body = format!("<shape type=\"sphere\"><bsdf type=\"diffuse\">{spectrum}</bsdf></shape>");
    let doc = read("reflectance", version, &body).unwrap();
    material(&doc, "reflectance")
}

/// The radiance an area emitter written with `spectrum` reads as.
fn radiance(version: &str, spectrum: &str) -> DVec3 {
    let body =
        format!("<shape type=\"sphere\"><emitter type=\"area\">{spectrum}</emitter></shape>");
    let doc = read("radiance", version, &body).unwrap();
    let Value::Array(shapes) = &doc.root.get("shapes").expect("shapes").value else {
        panic!()
    };
    let Value::Table(shape) = &shapes[0].value else {
        panic!()
    };
    rgb(shape, "emission")
}

#[track_caller]
fn close(got: DVec3, want: [f64; 3], tolerance: f64) {
    let want = DVec3::from_array(want);
    let err = ((got - want).abs() / want.abs().max(DVec3::ONE)).max_element();
    assert!(err < tolerance, "{got} vs Mitsuba's {want}");
}

/// A reflectance spectrum is seen under D65, clamped to [0, 1], and zero outside its range;
/// the values are Mitsuba 3's (see the module's comment for the command).
#[test]
fn reflectance_spectra_are_mitsuba_3s_colours() {
    let refl = |s: &str| {
        reflectance(
            "3.0.0",
            &format!("<spectrum name=\"reflectance\" value=\"{s}\"/>"),
        )
    };
    close(
        refl("400:0.1, 500:0.5, 600:0.8, 700:0.3"),
        [0.752187, 0.645269, 0.271706],
        1e-4,
    );
    // A flat spectrum of 1 is white (to Mitsuba's rounding of its D65 normalisation).
    close(refl("360:1, 830:1"), [0.998985, 0.998874, 0.998802], 1e-4);
    // Spaces alone separate pairs too; outside 400 to 700 nm nothing reflects.
    close(
        refl("400:0.78 500:0.78 600:0.78 700:0.78"),
        [0.776367, 0.77981, 0.776029],
        1e-4,
    );
    // Out of gamut: the negative components clamped to 0.
    close(refl("600:1, 650:1"), [0.748683, 0.0, 0.0], 1e-4);
    // One value is a grey, as before.
    close(refl("0.5"), [0.5, 0.5, 0.5], 1e-12);
}

/// An emitter's spectrum is not weighted by an illuminant and not clamped above; a flat one
/// is the sRGB colour of the flat spectrum (Mitsuba 3's `xyz_to_srgb(1)`), not a grey.
#[test]
fn emission_spectra_are_mitsuba_3s_colours() {
    let emit = |s: &str| {
        radiance(
            "3.0.0",
            &format!("<spectrum name=\"radiance\" value=\"{s}\"/>"),
        )
    };
    close(
        emit("400:0, 500:8, 600:15.6, 700:18.4"),
        [20.7108, 10.8546, 2.77115],
        1e-4,
    );
    close(emit("360:1, 830:1"), [1.20488, 0.948228, 0.909267], 1e-4);
    close(emit("10"), [12.0479, 9.48291, 9.08916], 1e-4);
    // So in files older than 2.0, as Mitsuba 3 reads them (Mitsuba 0.6's RGB builds read one
    // value as a grey; Mitsuba 3.9.1 loading a 0.6.0 file gives a point light's intensity 6
    // the colour [7.22876, 5.68975, 5.4535]).
    close(
        radiance("0.6.0", "<spectrum name=\"radiance\" value=\"10\"/>"),
        [12.0479, 9.48291, 9.08916],
        1e-4,
    );
}

/// A conductor's `eta` and `k` given as spectra are seen under D65 but not clamped above 1.
#[test]
fn conductor_indices_as_spectra_are_unbounded() {
    let body = "<shape type=\"sphere\"><bsdf type=\"conductor\">\
        <spectrum name=\"eta\" value=\"400:1, 700:2\"/><spectrum name=\"k\" value=\"400:3, 700:3\"/>\
        </bsdf></shape>";
    let doc = read("conductor-spectra", "3.0.0", body).unwrap();
    close(material(&doc, "eta"), [1.79949, 1.47621, 1.13095], 1e-4);
    close(material(&doc, "k"), [2.98603, 2.99927, 2.98473], 1e-4);
}

/// `<spectrum filename>`: a `.spd` file of `wavelength value` lines, `#` comments and blank
/// lines allowed, found as the scene's other files are.
#[test]
fn spectrum_files_are_read_and_resolved() {
    let dir = temp_dir("spectra-spd");
    std::fs::create_dir_all(dir.join("data")).unwrap();
    write(
        &dir,
        "data/t.spd",
        "# a test\n400 0.2\n500 0.9\n\n600 0.4 # peak\n700 0.1\n",
    );
    let text = "<scene version=\"3.0.0\"><path value=\"data\"/>\
        <shape type=\"sphere\"><bsdf type=\"diffuse\">\
        <spectrum name=\"reflectance\" filename=\"t.spd\"/></bsdf></shape></scene>";
    let path = write(&dir, "scene.xml", text);
    let (doc, _) = read_xml(&path, &[], false).unwrap();
    // Mitsuba 3: [0.195079, 0.728061, 0.569967] for the same file.
    close(
        material(&doc, "reflectance"),
        [0.195079, 0.728061, 0.569967],
        1e-4,
    );
}

/// Mitsuba 0.6's RGB builds have three spectral samples: three values are r, g, b in a file
/// older than 2.0. Mitsuba 3 refuses them ("Invalid spectrum value "0.2" (expected
/// wavelength:value pairs)"), in any file; so does foton in files of 2.0 and later.
#[test]
fn three_values_are_rgb_in_files_older_than_2() {
    let three = "<spectrum name=\"reflectance\" value=\"0.2, 0.4, 0.6\"/>";
    close(reflectance("0.6.0", three), [0.2, 0.4, 0.6], 1e-12);
    close(
        reflectance("0.5.0", &three.replace(", ", " ")),
        [0.2, 0.4, 0.6],
        1e-12,
    );
    let body = format!("<shape type=\"sphere\"><bsdf type=\"diffuse\">{three}</bsdf></shape>");
    let e = read("three-v3", "3.0.0", &body).unwrap_err();
    assert!(
        e.contains("scene.xml:3") && e.contains("reflectance"),
        "{e}"
    );
    assert!(
        e.contains("wavelength:value pairs") && e.contains("<rgb>"),
        "{e}"
    );
}

/// Spectra in files older than 2.0 are reduced as Mitsuba 3 reduces them, since it reads
/// those files too (`mi.traverse` of a 0.6.0 file in 3.9.1 `scalar_rgb`: a diffuse
/// reflectance `400:0.2, 500:0.5, 600:0.7, 700:0.8` is [0.757277, 0.591236, 0.328793]), not as
/// Mitsuba 0.6 did (without D65, ramped to zero one average spacing past their ends).
#[test]
fn spectra_in_files_older_than_2_are_mitsuba_3s_colours() {
    let flat = Spectrum::new(vec![360.0, 830.0], vec![1.0, 1.0]).unwrap();
    close(flat.to_srgb_v06(), [1.20488, 0.948228, 0.909267], 1e-4);
    let pairs = "400:0.2, 500:0.5, 600:0.7, 700:0.8";
    let got = reflectance(
        "0.6.0",
        &format!("<spectrum name=\"reflectance\" value=\"{pairs}\"/>"),
    );
    close(got, [0.757277, 0.591236, 0.328793], 1e-5);
    // Not Mitsuba 0.6's colour of the same pairs.
    let ramped = Spectrum::parse_pairs(&format!("300:0, {pairs}, 800:0")).unwrap();
    assert!((got - ramped.to_srgb_v06()).abs().max_element() > 0.05);
}

/// Blackbodies: Mitsuba 0.6's `<blackbody temperature="5000K" scale="2"/>` (its RGB
/// reduction of Planck's law, in W m⁻² sr⁻¹ nm⁻¹), and Mitsuba 3's `<spectrum
/// type="blackbody">`, which its RGB variants cannot render: read as its spectral variants
/// render it, Planck's law reduced as an emission.
#[test]
fn blackbodies_read_as_each_version_reduces_them() {
    // Mitsuba 3.9.1's scalar_spectral `blackbody` at 5000 K, 500 nm: 12107.17.
    assert!((spectrum::blackbody(500.0, 5000.0) / 12107.1689 - 1.0).abs() < 1e-5);
    assert!((spectrum::blackbody_v06(500.0, 5000.0) / 12107.1689 - 1.0).abs() < 1e-5);
    let v06 = radiance(
        "0.6.0",
        "<blackbody name=\"radiance\" temperature=\"5000K\" scale=\"2\"/>",
    );
    let want = spectrum::to_srgb_v06(|l| spectrum::blackbody_v06(l, 5000.0), &[]) * 2.0;
    close(v06, want.to_array(), 1e-12);
    // Warm white: red above green above blue, luminance near the curve's mean ȳ-weighted.
    assert!(v06.x > v06.y && v06.y > v06.z && v06.z > 0.0, "{v06}");
    // Mitsuba 3: its spectral variant's blackbody tabulated every 0.5 nm from 360 to 830 nm
    // and passed to `mi.spectrum_list_to_srgb(wavelengths, values, False, False)` gives
    // [15263, 12082.5, 9592.56].
    let v3 = radiance(
        "3.0.0",
        "<spectrum type=\"blackbody\" name=\"radiance\"><float name=\"temperature\" value=\"5000\"/></spectrum>",
    );
    close(v3, [15263.0, 12082.5, 9592.56], 1e-4);
    // 0.6's element is not Mitsuba 3's.
    let e = read(
        "blackbody-v3",
        "3.0.0",
        "<shape type=\"sphere\"><emitter type=\"area\"><blackbody name=\"radiance\" temperature=\"5000K\"/></emitter></shape>",
    )
    .unwrap_err();
    assert!(
        e.contains("spectrum type=\\\"blackbody\\\"") || e.contains("spectrum type=\"blackbody\""),
        "{e}"
    );
}

/// Mitsuba 3's other spectrum plugins written as objects: `irregular`, `regular`, `uniform`,
/// `d65`, `srgb`; other types (`bitmap`) are textures.
#[test]
fn spectrum_plugins_written_as_objects() {
    let irregular = reflectance(
        "3.0.0",
        "<spectrum type=\"irregular\" name=\"reflectance\"><string name=\"wavelengths\" value=\"400, 500, 600, 700\"/>\
         <string name=\"values\" value=\"0.1, 0.5, 0.8, 0.3\"/></spectrum>",
    );
    close(irregular, [0.752187, 0.645269, 0.271706], 1e-4);
    let regular = reflectance(
        "3.0.0",
        "<spectrum type=\"regular\" name=\"reflectance\"><float name=\"wavelength_min\" value=\"400\"/>\
         <float name=\"wavelength_max\" value=\"700\"/><string name=\"values\" value=\"0.1, 0.5, 0.8, 0.3\"/></spectrum>",
    );
    close(regular, [0.752187, 0.645269, 0.271706], 1e-4);
    let uniform = reflectance(
        "3.0.0",
        "<spectrum type=\"uniform\" name=\"reflectance\"><float name=\"value\" value=\"0.25\"/></spectrum>",
    );
    close(uniform, [0.25; 3], 1e-12);
    // Mitsuba 3's RGB variants expand `d65` into its colour times its scale (1 by default).
    let d65 = radiance(
        "3.0.0",
        "<spectrum type=\"d65\" name=\"radiance\"><float name=\"scale\" value=\"3\"/></spectrum>",
    );
    close(d65, [3.0; 3], 1e-12);
    let e = read(
        "spectrum-object-typo",
        "3.0.0",
        "<shape type=\"sphere\"><bsdf type=\"diffuse\"><spectrum type=\"uniform\" name=\"reflectance\">\
         <float name=\"valeu\" value=\"0.25\"/></spectrum></bsdf></shape>",
    )
    .unwrap_err();
    assert!(e.contains("scene.xml:3") && e.contains("valeu"), "{e}");
}

/// The named conductors' indices computed from their measured spectra equal Mitsuba 3's
/// (`mi.traverse` of `<bsdf type="conductor"><string name="material" value="Au"/>` in
/// scalar_rgb: eta [0.143036, 0.375307, 1.44205], k [3.983, 2.38556, 1.60336]; Cu: eta
/// [0.201005, 0.92375, 1.10222], k [3.91326, 2.45305, 2.14209]).
#[test]
fn named_conductors_are_their_spectra_reduced() {
    let (eta, k) = spectrum::conductor("Au").unwrap();
    close(
        eta.to_srgb(Quantity::Emission),
        [0.143036, 0.375307, 1.44205],
        1e-4,
    );
    close(
        k.to_srgb(Quantity::Emission),
        [3.983, 2.38556, 1.60336],
        1e-4,
    );
    let (eta, k) = foton_core::material::conductor_ior("Cu").unwrap();
    close(eta.as_dvec3(), [0.201005, 0.92375, 1.10222], 1e-4);
    close(k.as_dvec3(), [3.91326, 2.45305, 2.14209], 1e-4);
    assert_eq!(foton_core::material::conductor_ior("gold"), None);
    // A conductor without `material` is Mitsuba 3's perfect mirror, in a file older than 2.0
    // too (Mitsuba 3.9.1 loads a 0.6.0 file's `<bsdf type="conductor"/>` as a
    // SmoothConductor of eta 0, k 1; Mitsuba 0.6 made it copper).
    let body = "<shape type=\"sphere\"><bsdf type=\"conductor\"/></shape>";
    for version in ["0.6.0", "3.0.0"] {
        let doc = read(&format!("conductor-{version}"), version, body).unwrap();
        let materials = table(&doc.root, "materials");
        let Value::Table(m) = &materials.0[0].1.value else {
            panic!()
        };
        assert_eq!(
            m.get("material").map(|n| &n.value),
            Some(&Value::Str("none".into())),
            "{version}"
        );
    }
    // Mitsuba 0.6's `extEta` (Mitsuba 3 has none) divides Mitsuba 3's indices.
    let body = "<shape type=\"sphere\"><bsdf type=\"conductor\">\
                <string name=\"material\" value=\"Au\"/><float name=\"extEta\" value=\"1.5\"/>\
                </bsdf></shape>";
    let doc = read("conductor-ext", "0.6.0", body).unwrap();
    close(
        material(&doc, "eta"),
        [0.143036 / 1.5, 0.375307 / 1.5, 1.44205 / 1.5],
        1e-4,
    );
}

/// Malformed spectra: the error names the file, the line and the property.
#[test]
fn malformed_spectra_are_errors_at_their_line() {
    let bad = |name: &str, spectrum: &str| {
        let body = format!(
            "<shape type=\"sphere\">\n<bsdf type=\"diffuse\">\n{spectrum}\n</bsdf></shape>"
        );
        read(name, "3.0.0", &body).unwrap_err()
    };
    for (name, spectrum, says) in [
        (
            "pair",
            "<spectrum name=\"reflectance\" value=\"400:0.1, 500-0.5\"/>",
            "`500-0.5` is not a wavelength:value pair",
        ),
        (
            "order",
            "<spectrum name=\"reflectance\" value=\"500:0.1, 400:0.5\"/>",
            "wavelengths must increase",
        ),
        (
            "one",
            "<spectrum name=\"reflectance\" value=\"500:0.1\"/>",
            "at least two",
        ),
        (
            "both",
            "<spectrum name=\"reflectance\" value=\"0.1\" filename=\"x.spd\"/>",
            "either `value` or `filename`",
        ),
        (
            "missing",
            "<spectrum name=\"reflectance\" filename=\"nowhere.spd\"/>",
            "filename=\"nowhere.spd\": no such file in",
        ),
    ] {
        let e = bad(name, spectrum);
        assert!(
            e.contains("scene.xml:5") && e.contains("name=\"reflectance\""),
            "{name}: {e}"
        );
        assert!(e.contains(says), "{name}: {e}");
    }
    // A malformed line of a .spd file is named by its number.
    let dir = temp_dir("spectra-spd-bad");
    write(&dir, "bad.spd", "400 0.2\n500 0.9 1.0\n");
    let text = "<scene version=\"3.0.0\">\n<shape type=\"sphere\"><bsdf type=\"diffuse\">\n\
        <spectrum name=\"reflectance\" filename=\"bad.spd\"/></bsdf></shape></scene>";
    let path = write(&dir, "scene.xml", text);
    let e = read_xml(&path, &[], false).unwrap_err().to_string();
    assert!(
        e.contains("scene.xml:3") && e.contains("bad.spd: line 2"),
        "{e}"
    );
}

/// Mitsuba 0.6's `<rgb value="#rrggbb">`: each channel over 255, not decoded from sRGB (its
/// `<srgb>` decodes); Mitsuba 3 ("could not parse RGB value") and foton refuse it in files
/// of 2.0 and later.
#[test]
fn hexadecimal_rgb_in_files_older_than_2() {
    let hex = "<rgb name=\"reflectance\" value=\"#ff8000\"/>";
    close(reflectance("0.6.0", hex), [1.0, 128.0 / 255.0, 0.0], 1e-12);
    let body = format!("<shape type=\"sphere\"><bsdf type=\"diffuse\">{hex}</bsdf></shape>");
    let e = read("hex-v3", "3.0.0", &body).unwrap_err();
    assert!(
        e.contains("scene.xml:3") && e.contains("not a list of numbers"),
        "{e}"
    );
}

/// Mitsuba 0.6's measured media (`<string name="material" value="Regular Milk"/>`): the
/// table's coefficients times 100, sigma_s reduced by (1 - g), then `scale`; names in any
/// case. Mitsuba 3 has none.
#[test]
fn measured_media_in_files_older_than_2() {
    let medium = |version: &str, name: &str, material: &str| {
        let body = format!(
            "<medium type=\"homogeneous\" id=\"m\"><string name=\"material\" value=\"{material}\"/>\
             <float name=\"scale\" value=\"0.5\"/></medium>\
             <shape type=\"sphere\"><ref name=\"interior\" id=\"m\"/></shape>"
        );
        read(name, version, &body)
    };
    let doc = medium("0.6.0", "milk", "regular milk").unwrap();
    let media = table(&doc.root, "media");
    let Value::Table(m) = &media.0[0].1.value else {
        panic!("{media:?}")
    };
    // Narasimhan et al. 2006: sigma_s (18.2052, 20.3826, 22.3698), sigma_a (0.00153, 0.00460,
    // 0.01993) per mm, g (0.750, 0.714, 0.681).
    let g = DVec3::new(0.75, 0.714, 0.681);
    let s = DVec3::new(18.2052, 20.3826, 22.3698) * 100.0 * (DVec3::ONE - g) * 0.5;
    close(rgb(m, "sigma_s"), s.to_array(), 1e-12);
    close(rgb(m, "sigma_a"), [0.0765, 0.23, 0.9965], 1e-12);
    let e = medium("0.6.0", "milk-typo", "Regular Milc").unwrap_err();
    assert!(e.contains("Regular Milc") && e.contains("Skimmilk"), "{e}");
    let e = medium("3.0.0", "milk-v3", "Skimmilk").unwrap_err();
    assert!(e.contains("not Mitsuba 3's"), "{e}");
}
