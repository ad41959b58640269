//! Mutated Mitsuba scenes through the whole loader: errors or scenes, never a panic.

/// A scene using much of what the reader maps.
const RICH: &str = r#"<scene version="3.0.0">
<default name="spp" value="4"/>
<default name="res" value="16"/>
<integrator type="volpath"><integer name="max_depth" value="6"/></integrator>
<sensor type="perspective">
<float name="fov" value="40"/>
<string name="fov_axis" value="x"/>
<transform name="to_world"><lookat origin="0, 1, 4" target="0, 0.5, 0" up="0, 1, 0"/></transform>
<sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
<film type="hdrfilm">
<integer name="width" value="$res"/><integer name="height" value="12"/>
<integer name="crop_offset_x" value="2"/><integer name="crop_width" value="10"/>
<rfilter type="mitchell"/>
</film>
</sensor>
<bsdf type="diffuse" id="checks">
<texture type="checkerboard" name="reflectance"><rgb name="color0" value="0.8, 0.2, 0.1"/><rgb name="color1" value="0.1"/>
<transform name="to_uv"><scale x="4" y="4"/></transform></texture>
</bsdf>
<bsdf type="roughconductor" id="gold"><string name="material" value="Au"/><float name="alpha" value="0.2"/></bsdf>
<bsdf type="twosided" id="two"><bsdf type="plastic"><rgb name="diffuse_reflectance" value="0.3, 0.5, 0.2"/></bsdf></bsdf>
<bsdf type="blendbsdf" id="mix"><float name="weight" value="0.3"/><ref id="checks"/><ref id="gold"/></bsdf>
<bsdf type="dielectric" id="glass"><string name="int_ior" value="bk7"/></bsdf>
<medium type="homogeneous" id="fog"><rgb name="sigma_t" value="0.5"/><rgb name="albedo" value="0.8"/>
<phase type="hg"><float name="g" value="0.4"/></phase></medium>
<shape type="rectangle"><transform name="to_world"><rotate x="1" angle="-90"/><scale value="3"/></transform><ref id="checks"/></shape>
<shape type="sphere"><point name="center" x="-1" y="0.5" z="0"/><float name="radius" value="0.5"/><ref id="mix"/></shape>
<shape type="cube"><transform name="to_world"><scale value="0.3"/><translate x="1" y="0.3"/></transform>
<bsdf type="null"/><ref name="interior" id="fog"/></shape>
<shape type="disk"><transform name="to_world"><translate y="0.01" z="1"/></transform><ref id="two"/></shape>
<shape type="cylinder"><point name="p0" x="0" y="0" z="-1"/><point name="p1" x="0" y="1" z="-1"/><float name="radius" value="0.2"/><ref id="glass"/></shape>
<shape type="rectangle"><transform name="to_world"><rotate x="1" angle="90"/><translate y="2.5"/></transform>
<emitter type="area"><rgb name="radiance" value="5"/></emitter></shape>
<emitter type="point"><point name="position" x="0" y="2" z="1"/><rgb name="intensity" value="2"/></emitter>
<emitter type="spot"><transform name="to_world"><lookat origin="1, 2, 1" target="0, 0, 0"/></transform><float name="cutoff_angle" value="30"/></emitter>
<emitter type="constant"><rgb name="radiance" value="0.1"/></emitter>
</scene>
"#;

/// Bytes changed, numbers replaced by extreme ones, lines dropped, repeated or swapped; read
/// strictly and leniently. `FOTON_FUZZ_XML=N` runs N instead of 1,500.
#[test]
fn mutated_mitsuba_scenes_are_errors_or_scenes_never_panics() {
    let n: usize = std::env::var("FOTON_FUZZ_XML")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1_500);
    let dir = std::env::temp_dir().join(format!("foton-xml-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("scene.xml");
    std::fs::write(&path, RICH).unwrap();
    crate::load::load_with(&path, &[], &[], false)
        .unwrap_or_else(|e| panic!("the base scene: {e}"));
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = |m: usize| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state % m.max(1) as u64) as usize
    };
    const NUMBERS: &[&str] = &[
        "0",
        "-1",
        "1e30",
        "-1e30",
        "nan",
        "inf",
        "3.5",
        "100000",
        "2147483648",
        "-0",
    ];
    let mut outcomes = [0usize; 2];
    for _ in 0..n {
        let mut text = RICH.to_string();
        for _ in 0..1 + next(3) {
            match next(4) {
                0 => {
                    let mut b = text.into_bytes();
                    let at = next(b.len());
                    let pool = b"<>/\"= ,$0-.ex";
                    match next(3) {
                        0 => b[at] = pool[next(pool.len())],
                        1 => b.insert(at, pool[next(pool.len())]),
                        _ => {
                            b.remove(at);
                        }
                    }
                    text = String::from_utf8_lossy(&b).into_owned();
                }
                1 => {
                    let spans: Vec<(usize, usize)> = {
                        let b = text.as_bytes();
                        let mut out = Vec::new();
                        let mut i = 0;
                        while i < b.len() {
                            if b[i].is_ascii_digit() {
                                let s = i;
                                while i < b.len() && (b[i].is_ascii_digit() || b[i] == b'.') {
                                    i += 1;
                                }
                                out.push((s, i));
                            }
                            i += 1;
                        }
                        out
                    };
                    if let Some(&(s, e)) = spans.get(next(spans.len())) {
                        text.replace_range(s..e, NUMBERS[next(NUMBERS.len())]);
                    }
                }
                2 => {
                    let mut lines: Vec<&str> = text.lines().collect();
                    let at = next(lines.len());
                    if next(2) == 0 {
                        lines.remove(at);
                    } else {
                        let l = lines[at];
                        lines.insert(next(lines.len()), l);
                    }
                    text = lines.join("\n");
                }
                _ => {
                    let mut lines: Vec<&str> = text.lines().collect();
                    let (a, b) = (next(lines.len()), next(lines.len()));
                    lines.swap(a, b);
                    text = lines.join("\n");
                }
            }
        }
        std::fs::write(&path, &text).unwrap();
        let lenient = next(2) == 0;
        match std::panic::catch_unwind(|| crate::load::load_with(&path, &[], &[], lenient)) {
            Ok(r) => outcomes[r.is_ok() as usize] += 1,
            Err(_) => panic!("the loader panicked on:\n{text}"),
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    assert!(
        outcomes[0] > n / 10 && outcomes[1] > n / 10,
        "errors, scenes: {outcomes:?}"
    );
}
