//! Loading a large Mitsuba serialized mesh (a benchmark, not a test): the 708x708 grid bent
//! into a sphere of the PLY benchmark (tests/benches/ply_load.rs), 1,002,528 triangles with
//! normals and uv, written as Mitsuba 0.6 writes a serialized file (version 4, single
//! precision, zlib's default level). Prints the seconds of the decode alone (inflate, then
//! bytes to positions, triangles, normals and uv) and of `foton_loader::load` of a scene
//! holding the mesh (read, decode, transform, closedness, BVH).
//!
//!   cargo bench -p foton-loader --bench serialized_load
//!
//! With FOTON_SERIALIZED_KEEP=1 the file stays where it prints, for Mitsuba 3 to load:
//!   python core/loader/benches/serialized_load_mitsuba.py FILE [runs]

use flate2::Compression;
use flate2::write::ZlibEncoder;
use std::f32::consts::PI;
use std::io::Write;
use std::time::Instant;

/// Vertices per side of the grid; (N - 1)^2 quads of two triangles.
const N: usize = 709;

fn sphere_serialized() -> Vec<u8> {
    let mut s = Vec::new();
    s.extend((0x1000u32 | 0x1 | 0x2).to_le_bytes());
    s.extend(b"sphere\0");
    s.extend(((N * N) as u64).to_le_bytes());
    s.extend(((2 * (N - 1) * (N - 1)) as u64).to_le_bytes());
    let (mut positions, mut uvs) = (Vec::new(), Vec::new());
    for i in 0..N {
        for j in 0..N {
            let (u, v) = (i as f32 / (N - 1) as f32, j as f32 / (N - 1) as f32);
            // Latitude strictly inside the poles, so that no triangle is degenerate.
            let (theta, phi) = (0.05 + 0.9 * PI * v, 2.0 * PI * u);
            positions.extend([
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            ]);
            uvs.extend([u, v]);
        }
    }
    // On the unit sphere the normals are the positions.
    for x in positions.iter().chain(&positions).chain(&uvs) {
        s.extend(x.to_le_bytes());
    }
    for i in 0..N - 1 {
        for j in 0..N - 1 {
            let a = (i * N + j) as u32;
            let (b, c, d) = (a + N as u32, a + N as u32 + 1, a + 1);
            for k in [a, b, c, a, c, d] {
                s.extend(k.to_le_bytes());
            }
        }
    }
    let mut file = vec![0x1C, 0x04, 0x04, 0x00];
    let mut z = ZlibEncoder::new(Vec::new(), Compression::default());
    z.write_all(&s).unwrap();
    file.extend(z.finish().unwrap());
    file.extend(0u64.to_le_bytes());
    file.extend(1u32.to_le_bytes());
    file
}

const SCENE: &str = r#"
[render]
integrator = "path"
[film]
width = 16
height = 16
[camera]
position = [0, 0, 4]
look_at = [0, 0, 0]
fov = 40
[materials.white]
type = "diffuse"
reflectance = [0.5, 0.5, 0.5]
[[shapes]]
type = "mesh"
file = "sphere.serialized"
material = "white"
[[lights]]
type = "point"
position = [0, 3, 3]
intensity = [1, 1, 1]
"#;

fn main() {
    let triangles = 2 * (N - 1) * (N - 1);
    let bytes = sphere_serialized();
    let dir = std::env::temp_dir().join(format!("foton-serialized-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mesh = dir.join("sphere.serialized");
    std::fs::write(&mesh, &bytes).unwrap();
    println!(
        "serialized: {:.1} MB, {} vertices, {triangles} triangles",
        bytes.len() as f64 / 1e6,
        N * N
    );
    let mut decode = Vec::new();
    for _ in 0..3 {
        let start = Instant::now();
        let raw = foton_loader::mesh::serialized::parse(&bytes, 0).unwrap();
        decode.push(start.elapsed().as_secs_f64());
        assert_eq!(raw.triangles.len(), triangles);
        assert_eq!(raw.normals.len(), N * N);
    }
    let scene = dir.join("scene.toml");
    std::fs::write(&scene, SCENE).unwrap();
    let start = Instant::now();
    let loaded = foton_loader::load(&scene, &[]).unwrap();
    let total = start.elapsed().as_secs_f64();
    assert_eq!(loaded.accel().primitives().len(), triangles);
    let best = decode.iter().cloned().fold(f64::INFINITY, f64::min);
    println!("decode:             {best:.3} s (best of 3)");
    println!("loader::load + BVH: {total:.3} s");
    if std::env::var_os("FOTON_SERIALIZED_KEEP").is_some() {
        println!("kept: {}", mesh.display());
    } else {
        let _ = std::fs::remove_dir_all(&dir);
    }
}
