//! The deployment scripts run without a cluster: the image's entrypoint
//! (deploy/docker/entrypoint.sh) and the Slurm job scripts (deploy/slurm/) with a stand-in
//! `foton` that records the command each would run, that command then run by the real program
//! in-process; the parts of a frame rendered and merged as the jobs would, and the merge
//! compared byte for byte with a single render. The image's layout is checked from the
//! Dockerfile.

use crate::deploy::{SMALL, args, deploy, image_path, manifest, read};
use foton_tests::{Run, foton, foton_with_plugins, repo_root, temp_dir};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A stand-in for `foton`: records its arguments (NUL-separated) in the file FOTON_STUB_ARGS
/// names and exits 0.
fn stub(dir: &Path) -> PathBuf {
    let path = dir.join("foton-stub");
    std::fs::write(
        &path,
        "#!/bin/sh\n: >\"$FOTON_STUB_ARGS\"\nfor a in \"$@\"; do printf '%s\\0' \"$a\" >>\"$FOTON_STUB_ARGS\"; done\n",
    )
    .unwrap();
    set_mode(&path, 0o755);
    path
}

fn set_mode(path: &Path, mode: u32) {
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(mode)).unwrap();
}

/// Runs `bash SCRIPT ARGS...` with FOTON set to the stub and `env`; returns its output and the
/// arguments it gave foton (None if it never ran foton).
fn run_script(
    script: &Path,
    args: &[String],
    env: &[(&str, &str)],
    dir: &Path,
) -> (Output, Option<Vec<String>>) {
    let record = dir.join("stub-args");
    let _ = std::fs::remove_file(&record);
    let mut cmd = Command::new("bash");
    cmd.arg(script)
        .args(args)
        .env("FOTON", stub(dir))
        .env("FOTON_STUB_ARGS", &record)
        .env_remove("JOB_COMPLETION_INDEX")
        .env_remove("SLURM_ARRAY_TASK_ID")
        .env_remove("SLURM_CPUS_PER_TASK")
        .env_remove("FOTON_THREADS");
    for (k, v) in env {
        cmd.env(k, v);
    }
    let out = cmd
        .output()
        .unwrap_or_else(|e| panic!("cannot run bash {}: {e}", script.display()));
    let recorded = std::fs::read(&record).ok().map(|bytes| {
        String::from_utf8(bytes)
            .unwrap()
            .split_terminator('\0')
            .map(str::to_string)
            .collect()
    });
    (out, recorded)
}

/// Runs the command a script gave the stub with the real foton, in-process; merge needs no
/// plugins, render and sweep get the test build's.
fn replay(argv: &[String]) -> Run {
    let argv: Vec<&str> = argv.iter().map(String::as_str).collect();
    let run = if argv[0] == "merge" {
        foton(&argv)
    } else {
        foton_with_plugins(&argv)
    };
    assert_eq!(
        run.code, 0,
        "foton {argv:?} failed: {}{}",
        run.stdout, run.stderr
    );
    run
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn localise(args: &[String], data: &Path) -> Vec<String> {
    args.iter()
        .map(|a| {
            if a.starts_with('/') {
                image_path(a, data).to_str().unwrap().to_string()
            } else {
                a.clone()
            }
        })
        .collect()
}

fn with_small(args: &[String]) -> Vec<String> {
    args.iter()
        .cloned()
        .chain(SMALL.iter().map(|s| s.to_string()))
        .collect()
}

fn is_png(path: &Path) -> bool {
    std::fs::read(path).is_ok_and(|b| b.starts_with(b"\x89PNG\r\n\x1a\n"))
}

/// Renders `scene` with `options` in one process and checks `merged` is byte-identical.
fn assert_same_as_single_render(merged: &Path, scene: &str, options: &[String], dir: &Path) {
    let single = dir.join("single.exr");
    let mut argv = vec!["render".to_string(), scene.to_string()];
    argv.extend(options.iter().cloned());
    argv.extend(["-o".into(), single.to_str().unwrap().into()]);
    replay(&argv);
    let (a, b) = (
        std::fs::read(merged).unwrap(),
        std::fs::read(&single).unwrap(),
    );
    assert!(
        a == b,
        "{} ({} bytes) differs from the single-process render {} ({} bytes)",
        merged.display(),
        a.len(),
        single.display(),
        b.len()
    );
}

fn entrypoint() -> PathBuf {
    deploy().join("docker/entrypoint.sh")
}

#[test]
fn the_frame_job_renders_through_the_entrypoint_and_merges_to_the_single_render() {
    let dir = temp_dir("k8s-frame");
    let data = dir.join("data");
    let parts = with_small(&localise(&args(&manifest("frame-parts.yaml")), &data));
    let merge = localise(&args(&manifest("frame-merge.yaml")), &data);
    let n: usize = parts[1].parse().unwrap();
    let outdir = PathBuf::from(&parts[2]);
    for i in 0..n {
        let index = i.to_string();
        let (out, argv) = run_script(
            &entrypoint(),
            &parts,
            &[("JOB_COMPLETION_INDEX", &index)],
            &dir,
        );
        assert!(out.status.success(), "pod {i}: {}", stderr(&out));
        let argv = argv.expect("the entrypoint did not run foton");
        let part = outdir.join(format!("part_{i}.exr"));
        let expected_head = [
            "render".to_string(),
            parts[3].clone(),
            "--part".into(),
            format!("{i}/{n}"),
            "-o".into(),
            part.to_str().unwrap().into(),
        ];
        assert_eq!(argv[..6], expected_head, "pod {i}: {argv:?}");
        assert_eq!(argv[6..], parts[4..], "pod {i}: the manifest's options");
        replay(&argv);
        assert!(part.is_file(), "pod {i} wrote no {}", part.display());
    }
    let (out, argv) = run_script(&entrypoint(), &merge, &[], &dir);
    assert!(out.status.success(), "merge: {}", stderr(&out));
    let argv = argv.expect("the entrypoint did not run foton merge");
    let mut expected = vec!["merge".to_string()];
    expected.extend((0..n).map(|i| {
        outdir
            .join(format!("part_{i}.exr"))
            .to_str()
            .unwrap()
            .into()
    }));
    expected.extend(["-o".into(), merge[3].clone()]);
    assert_eq!(argv, expected);
    replay(&argv);
    assert_same_as_single_render(Path::new(&merge[3]), &parts[3], &parts[4..], &dir);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_entrypoint_refuses_to_run_a_part_without_its_index() {
    let dir = temp_dir("k8s-no-index");
    let parts = with_small(&localise(&args(&manifest("frame-parts.yaml")), &dir));
    let unset: &[(&str, &str)] = &[];
    let cases: [(&[(&str, &str)], &str); 4] = [
        (unset, "JOB_COMPLETION_INDEX is not set"),
        (
            &[("JOB_COMPLETION_INDEX", "")],
            "JOB_COMPLETION_INDEX is not set",
        ),
        (&[("JOB_COMPLETION_INDEX", "one")], "not an index"),
        (&[("JOB_COMPLETION_INDEX", "9999")], "outside the"),
    ];
    for (env, message) in cases {
        let (out, argv) = run_script(&entrypoint(), &parts, env, &dir);
        assert!(!out.status.success(), "{env:?} was accepted");
        let err = stderr(&out);
        assert!(err.contains(message), "{env:?}: {err}");
        assert!(argv.is_none(), "{env:?}: foton ran anyway: {argv:?}");
    }
    let (out, _) = run_script(&entrypoint(), &parts, unset, &dir);
    assert!(
        stderr(&out).contains("Indexed Job"),
        "the error should say how to run it: {}",
        stderr(&out)
    );
    // Only the part and cell commands need an index: the rest is foton's.
    let (out, argv) = run_script(&entrypoint(), &["plugins".to_string()], unset, &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(argv.unwrap(), ["plugins"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_sweep_jobs_render_cells_through_the_entrypoint_and_assemble_a_grid() {
    let dir = temp_dir("k8s-sweep");
    let data = dir.join("data");
    let cells = localise(&args(&manifest("sweep-cells.yaml")), &data);
    let cells = with_small(&cells);
    let assemble = localise(&args(&manifest("sweep-assemble.yaml")), &data);
    // The same small film for the assemble: its options must be the cells'.
    let k = assemble.len() - 5;
    let assemble: Vec<String> = assemble[..k]
        .iter()
        .cloned()
        .chain(SMALL.iter().map(|s| s.to_string()))
        .chain(assemble[k..].iter().cloned())
        .collect();
    let n = manifest("sweep-cells.yaml")["spec"]["completions"]
        .as_i64()
        .unwrap();
    let cells_dir = PathBuf::from(&cells[1]);
    for i in 0..n {
        let index = i.to_string();
        let (out, argv) = run_script(
            &entrypoint(),
            &cells,
            &[("JOB_COMPLETION_INDEX", &index)],
            &dir,
        );
        assert!(out.status.success(), "pod {i}: {}", stderr(&out));
        let argv = argv.expect("the entrypoint did not run foton");
        assert_eq!(argv[..2], ["sweep".to_string(), cells[2].clone()]);
        assert_eq!(
            argv[2..],
            cells[3..]
                .iter()
                .cloned()
                .chain([
                    "--cell".into(),
                    index.clone(),
                    "--cells-dir".into(),
                    cells[1].clone()
                ])
                .collect::<Vec<_>>()
        );
        replay(&argv);
        let cell = cells_dir.join(format!("cell-{i}.exr"));
        assert!(cell.is_file(), "pod {i} wrote no {}", cell.display());
    }
    let (out, argv) = run_script(&entrypoint(), &assemble, &[], &dir);
    assert!(out.status.success(), "assemble: {}", stderr(&out));
    assert_eq!(argv.as_ref(), Some(&assemble), "passed to foton as is");
    replay(&assemble);
    let grid = PathBuf::from(assemble.last().unwrap());
    assert!(is_png(&grid), "{} is not a PNG", grid.display());
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------------------------------------
// Slurm scripts
// ---------------------------------------------------------------------------------------------

#[test]
fn the_slurm_scripts_parse_and_map_the_array_task_to_the_share() {
    let slurm = deploy().join("slurm");
    let mut scripts: Vec<PathBuf> = std::fs::read_dir(&slurm)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "sh" || e == "sbatch"))
        .collect();
    scripts.push(entrypoint());
    scripts.sort();
    assert!(scripts.len() >= 8, "{scripts:?}");
    for script in &scripts {
        let out = Command::new("bash").arg("-n").arg(script).output().unwrap();
        assert!(
            out.status.success(),
            "bash -n {}: {}",
            script.display(),
            stderr(&out)
        );
        let text = read(script);
        // submit-common.sh is sourced by the submit scripts, whose options it inherits.
        if !script.ends_with("submit-common.sh") {
            assert!(
                text.starts_with("#!/usr/bin/env bash\n"),
                "{}: no bash shebang",
                script.display()
            );
            use std::os::unix::fs::PermissionsExt;
            let mode = std::fs::metadata(script).unwrap().permissions().mode();
            assert!(mode & 0o111 != 0, "{} is not executable", script.display());
            assert!(
                text.contains("\nset -euo pipefail\n"),
                "{}: no set -euo pipefail",
                script.display()
            );
        }
    }
    let part = read(&slurm.join("frame-part.sbatch"));
    assert!(
        part.contains("--part \"$part/$parts\"") && part.contains("part=$SLURM_ARRAY_TASK_ID"),
        "frame-part.sbatch must render --part SLURM_ARRAY_TASK_ID/N"
    );
    let cell = read(&slurm.join("sweep-cell.sbatch"));
    assert!(
        cell.contains("--cell \"$SLURM_ARRAY_TASK_ID\""),
        "sweep-cell.sbatch must render --cell SLURM_ARRAY_TASK_ID"
    );
    let submit = read(&slurm.join("submit-frame.sh"));
    assert!(
        submit.contains("--dependency=\"afterok:$parts_job\""),
        "the merge must wait for every part (afterok)"
    );
}

#[test]
fn the_slurm_array_renders_the_parts_and_the_merge_job_merges_them() {
    let dir = temp_dir("slurm-frame");
    let slurm = deploy().join("slurm");
    let outdir = dir.join("frame");
    std::fs::create_dir_all(&outdir).unwrap();
    let scene = repo_root().join("scenes/cornell-box.toml");
    let options: Vec<String> = ["--spp", "2", "--seed", "5"]
        .iter()
        .chain(SMALL.iter())
        .map(|s| s.to_string())
        .collect();
    let n = 3;
    let mut part_args = vec![
        n.to_string(),
        outdir.to_str().unwrap().into(),
        scene.to_str().unwrap().into(),
    ];
    part_args.extend(options.iter().cloned());

    // Outside an array there is no share to render.
    let (out, argv) = run_script(&slurm.join("frame-part.sbatch"), &part_args, &[], &dir);
    assert!(!out.status.success() && argv.is_none());
    assert!(
        stderr(&out).contains("SLURM_ARRAY_TASK_ID is not set"),
        "{}",
        stderr(&out)
    );

    for i in 0..n {
        let task = i.to_string();
        let (out, argv) = run_script(
            &slurm.join("frame-part.sbatch"),
            &part_args,
            &[("SLURM_ARRAY_TASK_ID", &task), ("SLURM_CPUS_PER_TASK", "2")],
            &dir,
        );
        assert!(out.status.success(), "task {i}: {}", stderr(&out));
        let argv = argv.expect("frame-part.sbatch did not run foton");
        let part = outdir.join(format!("part_{i}.exr"));
        let mut expected = vec![
            "render".to_string(),
            scene.to_str().unwrap().into(),
            "--part".into(),
            format!("{i}/{n}"),
            "-o".into(),
            part.to_str().unwrap().into(),
            "--threads".into(),
            "2".into(),
        ];
        expected.extend(options.iter().cloned());
        assert_eq!(argv, expected);
        replay(&argv);
        assert!(part.is_file());
    }
    let merged = dir.join("frame.exr");
    let (out, argv) = run_script(
        &slurm.join("frame-merge.sbatch"),
        &[
            n.to_string(),
            outdir.to_str().unwrap().into(),
            merged.to_str().unwrap().into(),
        ],
        &[],
        &dir,
    );
    assert!(out.status.success(), "merge: {}", stderr(&out));
    replay(&argv.expect("frame-merge.sbatch did not run foton"));
    assert_same_as_single_render(&merged, scene.to_str().unwrap(), &options, &dir);
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------------------------------------
// The image
// ---------------------------------------------------------------------------------------------

#[test]
fn the_image_puts_the_plugins_beside_foton_and_runs_the_entrypoint() {
    let dockerfile = read(&repo_root().join("Dockerfile"));
    let lines: Vec<&str> = dockerfile
        .lines()
        .map(str::trim)
        .filter(|l| !l.starts_with('#'))
        .collect();
    let froms = lines.iter().filter(|l| l.starts_with("FROM ")).count();
    assert!(froms >= 2, "a build stage and a runtime stage expected");
    // The plugins are built with foton and copied to its folder, where it looks for them.
    assert!(
        dockerfile.contains("cp target/release/foton target/release/libfoton_*.so /out/")
            && lines.contains(&"COPY --from=build /out/ /opt/foton/"),
        "foton and its plugins must land in one folder"
    );
    // The path plugin's x86-64-v3 copy lands in the subfolder the plugin search tries first.
    assert!(
        dockerfile.contains("cp -r target/release/x86-64-v3 /out/"),
        "the x86-64-v3 plugins must land in /opt/foton/x86-64-v3"
    );
    assert!(dockerfile.contains("ENV PATH=/opt/foton:$PATH"));
    // The entrypoint is the repository's script, copied to where ENTRYPOINT names it.
    let entry = lines
        .iter()
        .find_map(|l| l.strip_prefix("ENTRYPOINT "))
        .expect("no ENTRYPOINT");
    let target = entry.trim_matches(|c| c == '[' || c == ']' || c == '"');
    assert!(
        lines.contains(&format!("COPY deploy/docker/entrypoint.sh {target}").as_str()),
        "ENTRYPOINT {target} is not the copy of deploy/docker/entrypoint.sh"
    );
    // The manifests render the image's example scenes.
    assert!(lines.contains(&"COPY scenes/ /opt/foton/scenes/"));
    for file in ["frame-parts.yaml", "sweep-cells.yaml"] {
        for a in args(&manifest(file)) {
            if a.starts_with("/opt/foton/scenes/") {
                let here = image_path(&a, Path::new("/nonexistent"));
                assert!(
                    here.is_file(),
                    "{file}: {a} is not in the image ({})",
                    here.display()
                );
            }
        }
    }
    // A build context without target/ (gigabytes) and .git.
    let ignore = read(&repo_root().join(".dockerignore"));
    for pattern in ["target/", ".git/"] {
        assert!(
            ignore.lines().any(|l| l.trim() == pattern),
            ".dockerignore lacks {pattern}"
        );
    }
}
