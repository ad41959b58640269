//! The deployment files of deploy/: what can be checked without a cluster. The Kubernetes
//! manifests (deploy/k8s/) are parsed and checked against each other (an Indexed Job whose
//! completions are the parts or cells, the merge Job on the same claim with the same N), and
//! their arguments are run: through the image's entrypoint (deploy/docker/entrypoint.sh) and
//! the Slurm job scripts (deploy/slurm/), with a stand-in `foton` that records the command
//! each would run, and that command then run by the real program in-process (the test
//! binary has no `foton` executable of its own). So the parts of a frame are rendered and
//! merged as the jobs would, and the merge compared byte for byte with a single render.
//! deploy/slurm/test-cluster.sh runs the Slurm side on a real one-node cluster (.ci/run).

use foton_tests::{Run, foton, foton_with_plugins, repo_root, temp_dir};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use yaml_rust2::{Yaml, YamlLoader};

/// Makes the test renders tiny; appended to the manifests' own render and sweep options.
const SMALL: [&str; 4] = ["--set", "film.width=16", "--set", "film.height=16"];

fn deploy() -> PathBuf {
    repo_root().join("deploy")
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

// ---------------------------------------------------------------------------------------------
// Kubernetes manifests
// ---------------------------------------------------------------------------------------------

/// deploy/k8s/NAME: exactly one YAML document.
fn manifest(name: &str) -> Yaml {
    let path = deploy().join("k8s").join(name);
    let mut docs = YamlLoader::load_from_str(&read(&path))
        .unwrap_or_else(|e| panic!("{}: not YAML: {e}", path.display()));
    assert_eq!(docs.len(), 1, "{}: one document expected", path.display());
    docs.remove(0)
}

fn str_at<'a>(doc: &'a Yaml, what: &str, value: &'a Yaml) -> &'a str {
    value
        .as_str()
        .unwrap_or_else(|| panic!("{}: {what} is not a string: {value:?}", name(doc)))
}

fn name(doc: &Yaml) -> String {
    format!(
        "{} {}",
        doc["kind"].as_str().unwrap_or("?"),
        doc["metadata"]["name"].as_str().unwrap_or("?")
    )
}

/// The one container of a Job's pod template.
fn container(job: &Yaml) -> &Yaml {
    let containers = job["spec"]["template"]["spec"]["containers"]
        .as_vec()
        .unwrap_or_else(|| panic!("{}: no containers", name(job)));
    assert_eq!(containers.len(), 1, "{}: one container expected", name(job));
    &containers[0]
}

fn args(job: &Yaml) -> Vec<String> {
    let c = container(job);
    assert!(
        c["command"].is_badvalue(),
        "{}: a command would replace the image's entrypoint",
        name(job)
    );
    c["args"]
        .as_vec()
        .unwrap_or_else(|| panic!("{}: no args", name(job)))
        .iter()
        .map(|a| str_at(job, "an argument", a).to_string())
        .collect()
}

/// The claim a Job's container mounts, and where.
fn mount(job: &Yaml) -> (String, String) {
    let c = container(job);
    let mounts = c["volumeMounts"].as_vec().expect("volumeMounts");
    assert_eq!(mounts.len(), 1, "{}: one volume mount expected", name(job));
    let (volume, path) = (
        str_at(job, "the mount's name", &mounts[0]["name"]),
        str_at(job, "the mount path", &mounts[0]["mountPath"]),
    );
    let volumes = job["spec"]["template"]["spec"]["volumes"]
        .as_vec()
        .expect("volumes");
    let v = volumes
        .iter()
        .find(|v| v["name"].as_str() == Some(volume))
        .unwrap_or_else(|| panic!("{}: no volume {volume}", name(job)));
    let claim = str_at(job, "claimName", &v["persistentVolumeClaim"]["claimName"]);
    (claim.to_string(), path.to_string())
}

fn int(job: &Yaml, key: &str) -> i64 {
    job["spec"][key]
        .as_i64()
        .unwrap_or_else(|| panic!("{}: spec.{key} is not an integer", name(job)))
}

/// Checks what a Job of N indexed pods needs: completionMode Indexed, N completions, a
/// parallelism within 1..=N, pods that are not restarted in place (a retry is a new pod).
fn assert_indexed(job: &Yaml, n: i64) {
    assert_eq!(
        job["apiVersion"].as_str(),
        Some("batch/v1"),
        "{}",
        name(job)
    );
    assert_eq!(job["kind"].as_str(), Some("Job"), "{}", name(job));
    assert_eq!(
        job["spec"]["completionMode"].as_str(),
        Some("Indexed"),
        "{}: without completionMode Indexed no pod gets JOB_COMPLETION_INDEX",
        name(job)
    );
    assert_eq!(int(job, "completions"), n, "{}: completions", name(job));
    let parallelism = int(job, "parallelism");
    assert!(
        (1..=n).contains(&parallelism),
        "{}: parallelism {parallelism} outside 1..={n}",
        name(job)
    );
    assert_eq!(
        job["spec"]["template"]["spec"]["restartPolicy"].as_str(),
        Some("Never"),
        "{}",
        name(job)
    );
}

/// A Job that runs once: no completionMode Indexed, one completion.
fn assert_single(job: &Yaml) {
    assert_eq!(job["kind"].as_str(), Some("Job"), "{}", name(job));
    assert_ne!(
        job["spec"]["completionMode"].as_str(),
        Some("Indexed"),
        "{}",
        name(job)
    );
    let completions = &job["spec"]["completions"];
    assert!(
        completions.is_badvalue() || completions.as_i64() == Some(1),
        "{}: one completion expected",
        name(job)
    );
}

/// The claim of pvc.yaml, which every Job must mount; it must be ReadWriteMany.
fn shared_claim() -> String {
    let pvc = manifest("pvc.yaml");
    assert_eq!(pvc["kind"].as_str(), Some("PersistentVolumeClaim"));
    let modes: Vec<&str> = pvc["spec"]["accessModes"]
        .as_vec()
        .expect("accessModes")
        .iter()
        .filter_map(Yaml::as_str)
        .collect();
    assert!(
        modes.contains(&"ReadWriteMany"),
        "the pods of a Job run on several nodes: the claim must be ReadWriteMany, not {modes:?}"
    );
    pvc["metadata"]["name"].as_str().expect("name").to_string()
}

fn assert_under(job: &Yaml, path: &str, mount_path: &str) {
    assert!(
        path.starts_with(&format!("{mount_path}/")),
        "{}: {path} is not on the shared volume ({mount_path})",
        name(job)
    );
}

#[test]
fn every_manifest_is_one_named_kubernetes_object() {
    let mut names = BTreeSet::new();
    let mut files: Vec<PathBuf> = std::fs::read_dir(deploy().join("k8s"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "yaml" || e == "yml"))
        .collect();
    files.sort();
    for expected in [
        "pvc.yaml",
        "frame-parts.yaml",
        "frame-merge.yaml",
        "sweep-cells.yaml",
        "sweep-assemble.yaml",
    ] {
        assert!(
            files.iter().any(|f| f.ends_with(expected)),
            "deploy/k8s/{expected} is missing"
        );
    }
    for file in &files {
        let doc = manifest(file.file_name().unwrap().to_str().unwrap());
        for key in ["apiVersion", "kind"] {
            assert!(doc[key].as_str().is_some(), "{}: no {key}", file.display());
        }
        let n = doc["metadata"]["name"]
            .as_str()
            .unwrap_or_else(|| panic!("{}: no metadata.name", file.display()));
        assert!(
            names.insert((doc["kind"].as_str().unwrap().to_string(), n.to_string())),
            "{}: a second {} named {n}",
            file.display(),
            name(&doc)
        );
    }
}

#[test]
fn frame_parts_are_an_indexed_job_and_the_merge_reads_the_same_parts() {
    let claim = shared_claim();
    let (parts, merge) = (manifest("frame-parts.yaml"), manifest("frame-merge.yaml"));
    let (p, m) = (args(&parts), args(&merge));
    // part N OUTDIR SCENE [option]... and merge-parts N OUTDIR OUTPUT (deploy/docker/entrypoint.sh).
    assert_eq!(p[0], "part", "{p:?}");
    assert_eq!(m[0], "merge-parts", "{m:?}");
    assert_eq!(m.len(), 4, "{m:?}");
    let n: i64 = p[1].parse().expect("N of part");
    assert_indexed(&parts, n);
    assert_single(&merge);
    assert_eq!(m[1], p[1], "the merge must expect the parts' N");
    assert_eq!(m[2], p[2], "the merge must read the folder the parts write");
    for job in [&parts, &merge] {
        let (job_claim, path) = mount(job);
        assert_eq!(job_claim, claim, "{}: mounts another claim", name(job));
        assert_eq!(path, mount(&parts).1, "{}: mounted elsewhere", name(job));
    }
    let mount_path = mount(&parts).1;
    assert_under(&parts, &p[2], &mount_path);
    assert_under(&merge, &m[3], &mount_path);
    assert_eq!(
        container(&parts)["image"].as_str(),
        container(&merge)["image"].as_str(),
        "parts and merge must come from the same build of foton"
    );
}

#[test]
fn sweep_cells_are_an_indexed_job_of_as_many_cells_as_foton_counts() {
    let claim = shared_claim();
    let (cells, assemble) = (
        manifest("sweep-cells.yaml"),
        manifest("sweep-assemble.yaml"),
    );
    let (c, a) = (args(&cells), args(&assemble));
    // cell CELLSDIR SCENE [sweep option]...; sweep SCENE [option]... --assemble --cells-dir
    // CELLSDIR -o OUTPUT (passed to foton as is).
    assert_eq!(c[0], "cell", "{c:?}");
    let (cells_dir, scene, options) = (&c[1], &c[2], &c[3..]);
    let tail = [
        "--assemble".to_string(),
        "--cells-dir".into(),
        cells_dir.clone(),
        "-o".into(),
    ];
    assert_eq!(a[0], "sweep", "{a:?}");
    assert_eq!(&a[1], scene, "cells and assemble must sweep the same scene");
    assert_eq!(
        &a[2..a.len() - 5],
        options,
        "cells and assemble must be given the same sweep options"
    );
    assert_eq!(a[a.len() - 5..a.len() - 1], tail, "{a:?}");

    // The number of cells is foton's to say, from the same options.
    // A scene of the image is a scene of the repository; nothing is written.
    let scene = image_path(scene, Path::new("/nonexistent"));
    let mut count = vec!["sweep", scene.to_str().unwrap()];
    count.extend(options.iter().map(String::as_str));
    count.push("--cells");
    let run = foton_with_plugins(&count);
    assert_eq!(run.code, 0, "{count:?}: {}", run.stderr);
    let n: i64 =
        run.stdout.trim().parse().unwrap_or_else(|_| {
            panic!("foton sweep --cells printed {:?}, not a number", run.stdout)
        });
    assert_indexed(&cells, n);
    assert_single(&assemble);
    let mount_path = mount(&cells).1;
    for job in [&cells, &assemble] {
        assert_eq!(
            mount(job),
            (claim.clone(), mount_path.clone()),
            "{}",
            name(job)
        );
    }
    assert_under(&cells, cells_dir, &mount_path);
    assert_under(&assemble, a.last().unwrap(), &mount_path);
}

/// The options `foton SUBCOMMAND --help` lists: the words that open its option lines
/// (`-o, --output <OUTPUT>` gives -o and --output).
fn help_flags(subcommand: &str) -> BTreeSet<String> {
    let run = foton(&[subcommand, "--help"]);
    assert_eq!(run.code, 0, "foton {subcommand} --help: {}", run.stderr);
    run.stdout
        .lines()
        .map(str::trim_start)
        .filter(|l| l.starts_with('-'))
        .flat_map(|l| {
            l.split_whitespace()
                .map(|w| w.trim_end_matches(','))
                .take_while(|w| w.starts_with('-'))
                .map(str::to_string)
                .collect::<Vec<_>>()
        })
        .collect()
}

/// The options in a list of arguments (`--spp`, `-o`; not `-1`).
fn arg_flags(args: &[String]) -> Vec<&str> {
    args.iter()
        .map(String::as_str)
        .filter(|a| {
            a.strip_prefix('-')
                .map(|r| r.trim_start_matches('-'))
                .and_then(|r| r.chars().next())
                .is_some_and(|c| c.is_ascii_lowercase())
        })
        .collect()
}

fn assert_flags_exist(subcommand: &str, flags: &[&str], whose: &str) {
    let known = help_flags(subcommand);
    let unknown: Vec<_> = flags.iter().filter(|f| !known.contains(**f)).collect();
    assert!(
        unknown.is_empty(),
        "{whose} gives foton {subcommand} {unknown:?}, which `foton {subcommand} --help` does not list ({known:?})"
    );
}

/// Whether `text` has `flag` as a word of its own (` --cell ` but not ` --cells-dir`).
fn mentions(text: &str, flag: &str) -> bool {
    text.match_indices(flag).any(|(i, _)| {
        let before = text[..i].chars().next_back();
        let after = text[i + flag.len()..].chars().next();
        before.is_some_and(char::is_whitespace)
            && !after.is_some_and(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
    })
}

#[test]
fn the_flags_the_jobs_pass_are_foton_flags() {
    // The subcommands and options each script gives foton itself.
    let uses: [(&str, &str, &[&str]); 8] = [
        (
            "docker/entrypoint.sh",
            "render",
            &["--part", "-o", "--threads"],
        ),
        ("docker/entrypoint.sh", "merge", &["-o"]),
        (
            "docker/entrypoint.sh",
            "sweep",
            &["--cell", "--cells-dir", "--threads"],
        ),
        (
            "slurm/frame-part.sbatch",
            "render",
            &["--part", "-o", "--threads"],
        ),
        ("slurm/frame-merge.sbatch", "merge", &["-o"]),
        (
            "slurm/sweep-cell.sbatch",
            "sweep",
            &["--cell", "--cells-dir", "--threads"],
        ),
        (
            "slurm/sweep-assemble.sbatch",
            "sweep",
            &["--assemble", "--cells-dir", "-o"],
        ),
        ("slurm/submit-sweep.sh", "sweep", &["--cells"]),
    ];
    for (script, subcommand, flags) in uses {
        let text = read(&deploy().join(script));
        // `"$foton" render "$scene"`, `"${FOTON:-foton}" merge "${files[@]}"`.
        assert!(
            text.contains(&format!("\" {subcommand} ")),
            "{script} does not run foton {subcommand}"
        );
        for flag in flags {
            assert!(mentions(&text, flag), "{script} does not give {flag}");
        }
        assert_flags_exist(subcommand, flags, script);
    }
    // And what the manifests pass on.
    let parts = args(&manifest("frame-parts.yaml"));
    assert_flags_exist("render", &arg_flags(&parts[4..]), "frame-parts.yaml");
    let cells = args(&manifest("sweep-cells.yaml"));
    assert_flags_exist("sweep", &arg_flags(&cells[3..]), "sweep-cells.yaml");
    let assemble = args(&manifest("sweep-assemble.yaml"));
    assert_flags_exist("sweep", &arg_flags(&assemble[2..]), "sweep-assemble.yaml");
}

// ---------------------------------------------------------------------------------------------
// Running the entrypoint and the Slurm scripts
// ---------------------------------------------------------------------------------------------

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

/// A path of the image (the Dockerfile copies scenes/ to /opt/foton/scenes/) or of the shared
/// volume (/data) as a path here.
fn image_path(path: &str, data: &Path) -> PathBuf {
    if let Some(rest) = path.strip_prefix("/opt/foton/scenes/") {
        repo_root().join("scenes").join(rest)
    } else if let Some(rest) = path.strip_prefix("/data/") {
        data.join(rest)
    } else {
        PathBuf::from(path)
    }
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
