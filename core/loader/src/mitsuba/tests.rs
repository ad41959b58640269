//! Mutated Mitsuba scenes through the whole loader: errors or scenes, never a panic.

/// A scene using much of what the reader maps.
const RICH: &str = r#"<scene version="3.0.0">
<default name="spp" value="4"/>
<default name="res" value="16"/>
<integrator type="volpath"><integer name="max_depth" value="6"/><float name="timeout" value="30"/></integrator>
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
<bsdf type="coating" id="coated"><rgb name="sigma_a" value="0.1, 0.2, 0.3"/><bsdf type="dielectric"/></bsdf>
<bsdf type="disneyglass" id="lj_glass"><rgb name="baseColor" value="0.8 0.6 0.2"/><float name="anisotropic" value="0.5"/></bsdf>
<bsdf type="disneysheen" id="lj_sheen"><float name="sheenTint" value="0.3"/></bsdf>
<bsdf type="disneyclearcoat" id="lj_coat"><float name="clearcoatGloss" value="0.2"/></bsdf>
<bsdf type="disneymetal" id="lj_metal"><float name="roughness" value="0.3"/></bsdf>
<medium type="homogeneous" id="fog"><rgb name="sigma_t" value="0.5"/><rgb name="albedo" value="0.8"/>
<phase type="hg"><float name="g" value="0.4"/></phase></medium>
<shape type="rectangle"><transform name="to_world"><rotate x="1" angle="-90"/><scale value="3"/></transform><ref id="checks"/></shape>
<shape type="sphere"><point name="center" x="-1" y="0.5" z="0"/><float name="radius" value="0.5"/><ref id="mix"/></shape>
<shape type="cube"><transform name="to_world"><scale value="0.3"/><translate x="1" y="0.3"/></transform>
<bsdf type="null"/><ref name="interior" id="fog"/></shape>
<shape type="disk"><transform name="to_world"><translate y="0.01" z="1"/></transform><ref id="two"/></shape>
<shape type="sphere"><point name="center" x="1.5" y="0.3" z="1"/><float name="radius" value="0.2"/><ref id="coated"/></shape>
<shape type="sphere"><point name="center" x="-1.5" y="0.3" z="1"/><float name="radius" value="0.2"/><ref id="lj_glass"/></shape>
<shape type="sphere"><point name="center" x="0" y="0.3" z="1.5"/><float name="radius" value="0.2"/><ref id="lj_sheen"/></shape>
<shape type="sphere"><point name="center" x="0.5" y="0.3" z="1.5"/><float name="radius" value="0.2"/><ref id="lj_coat"/></shape>
<shape type="sphere"><point name="center" x="-0.5" y="0.3" z="1.5"/><float name="radius" value="0.2"/><ref id="lj_metal"/></shape>
<shape type="cylinder"><point name="p0" x="0" y="0" z="-1"/><point name="p1" x="0" y="1" z="-1"/><float name="radius" value="0.2"/><ref id="glass"/></shape>
<shape type="rectangle"><transform name="to_world"><rotate x="1" angle="90"/><translate y="2.5"/></transform>
<emitter type="area"><rgb name="radiance" value="5"/></emitter></shape>
<emitter type="point"><point name="position" x="0" y="2" z="1"/><rgb name="intensity" value="2"/></emitter>
<emitter type="spot"><transform name="to_world"><lookat origin="1, 2, 1" target="0, 0, 0"/></transform><float name="cutoff_angle" value="30"/></emitter>
<emitter type="constant"><rgb name="radiance" value="0.1"/></emitter>
</scene>
"#;

/// The mutation test (`crate::mutations`) on that scene. `FOTON_FUZZ_XML=N` runs N cases
/// instead of 1,500.
#[test]
fn mutated_mitsuba_scenes_are_errors_or_scenes_never_panics() {
    let n = crate::mutations::count("FOTON_FUZZ_XML", 1_500);
    let dir = std::env::temp_dir().join(format!("foton-xml-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    crate::mutations::check(
        &dir.join("scene.xml"),
        RICH,
        b"<>/\"= ,$0-.ex",
        n,
        0x2545_f491_4f6c_dd1d,
    );
    let _ = std::fs::remove_dir_all(&dir);
}
