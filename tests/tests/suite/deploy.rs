//! The deployment files of deploy/: what can be checked without a cluster. The Kubernetes
//! manifests (deploy/k8s/) are parsed and checked against each other (an Indexed Job whose
//! completions are the parts or cells, the merge Job on the same claim with the same N), and
//! the flags their jobs pass against foton's own. Their arguments are run through the
//! image's entrypoint and the Slurm scripts in deploy_scripts.rs. deploy/slurm/test-cluster.sh
//! runs the Slurm side on a real one-node cluster (.ci/run).

use foton_tests::{foton, foton_with_plugins, repo_root};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use yaml_rust2::{Yaml, YamlLoader};

/// Makes the test renders tiny; appended to the manifests' own render and sweep options.
pub(crate) const SMALL: [&str; 4] = ["--set", "film.width=16", "--set", "film.height=16"];

pub(crate) fn deploy() -> PathBuf {
    repo_root().join("deploy")
}

pub(crate) fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

// ---------------------------------------------------------------------------------------------
// Kubernetes manifests
// ---------------------------------------------------------------------------------------------

/// deploy/k8s/NAME: exactly one YAML document.
pub(crate) fn manifest(name: &str) -> Yaml {
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

pub(crate) fn args(job: &Yaml) -> Vec<String> {
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

/// A path of the image (the Dockerfile copies scenes/ to /opt/foton/scenes/) or of the shared
/// volume (/data) as a path here.
pub(crate) fn image_path(path: &str, data: &Path) -> PathBuf {
    if let Some(rest) = path.strip_prefix("/opt/foton/scenes/") {
        repo_root().join("scenes").join(rest)
    } else if let Some(rest) = path.strip_prefix("/data/") {
        data.join(rest)
    } else {
        PathBuf::from(path)
    }
}
