//! foton's integration tests, one test binary for all of them: physics checks, plugins,
//! scenes, tools, bad input. One binary instead of one per file, because each binary links
//! core, the loader and the program again (42 links, and the compile time of the test
//! command was mostly that). Each file is a module; run one file's tests with
//! `cargo test --release -p foton-tests --test suite vpm::`.
//!
//! Two files stay binaries of their own (tests/tests/ppb_interrupt.rs and
//! sppm_interrupt.rs): they raise the process-wide interrupt flag that every in-process
//! render watches, and would stop the renders of tests running beside them.

mod alpha;
mod ao;
mod bad_input;
mod bad_input_output;
mod bad_input_plugins;
mod bad_input_values;
mod bdpt;
mod beams;
mod bitterli;
mod blend;
mod build_id;
mod capabilities;
mod coated;
mod coating;
mod collimated;
mod conductor;
mod consistency;
mod crossing_limit;
mod curves;
mod deploy;
mod deploy_scripts;
mod directional;
mod disc_edges;
mod disc_estimate;
mod docs;
mod emissive_media;
mod environment;
mod filter;
mod glossy;
mod heterogeneous;
mod kernels;
mod lajolla;
mod lobes;
mod materials_classic;
mod media;
mod media_sides;
mod medium_kind;
mod mesh_attribute;
mod meters;
mod mitsuba;
mod mitsuba05;
mod mitsuba_document;
mod mitsuba_fixtures;
mod mitsuba_materials;
mod mitsuba_shapes;
mod normal_map;
mod one_sided;
mod orthographic;
mod parts;
mod pbrt;
mod photon;
mod photon_coats;
mod physics;
mod plugin_api;
mod plugins;
mod ply;
mod ppb;
mod pplastic;
mod principled;
mod projector;
mod rough_texture;
mod samplers;
mod sampling;
mod sampling_lights;
mod sampling_materials;
mod sampling_media;
mod scenes;
mod sdfgrid;
mod shapes;
mod spectra;
mod sphere_light;
mod sphere_uv;
mod spot;
mod sppm;
mod sunsky;
mod techniques;
mod textured_light;
mod textures;
mod thin_dielectric;
mod thin_lens;
mod time_limit;
mod tonemap;
mod tools;
mod tools_bad_input;
mod twosided_emitter;
mod vcm;
mod volume_photons;
mod vpm;
mod white_balance;
