//! The command line on good and bad input: bad input exits non-zero with one located line.

use assert_cmd::Command;
use std::path::Path;

fn prism() -> Command {
    Command::cargo_bin("prism").unwrap()
}

fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

const GOOD: &str = r#"Scene(
    render: (width: 8, height: 6, spp: 2),
    camera: (position: (0.0, 0.0, 4.0), look_at: (0.0, 0.0, 0.0)),
    environment: Constant(Rgb(0.5, 0.5, 0.5)),
    entities: [
        (name: "ball", shape: Sphere(center: (0.0, 0.0, 0.0), radius: 1.0),
         material: Diffuse(albedo: Rgb(0.5, 0.5, 0.5))),
    ],
)"#;

/// Runs `prism ARGS` and returns stderr, asserting failure and a single-line message.
fn fails(args: &[&str]) -> String {
    let out = prism().args(args).output().unwrap();
    assert!(!out.status.success(), "{args:?} should fail");
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
    assert!(!err.contains("panicked"), "{err}");
    err
}

#[test]
fn renders_png_and_exr() {
    let d = tempfile::tempdir().unwrap();
    let scene = write(d.path(), "s.ron", GOOD);
    for name in ["out.png", "out.exr"] {
        let out = d.path().join(name);
        prism()
            .args([
                "render",
                scene.to_str().unwrap(),
                "-o",
                out.to_str().unwrap(),
                "--quiet",
            ])
            .assert()
            .success();
        let (img, meta) = prism::film::read_image(&out).unwrap();
        assert_eq!((img.width, img.height), (8, 6));
        if name.ends_with("exr") {
            assert_eq!(meta.unwrap().spp, 2);
        }
    }
    let names: Vec<_> = std::fs::read_dir(d.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 3, "no temporary files left: {names:?}");
}

#[test]
fn info_prints_the_effects_manifest() {
    let d = tempfile::tempdir().unwrap();
    let scene = write(d.path(), "s.ron", GOOD);
    let out = prism()
        .args(["info", scene.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(out.status.success());
    let s = String::from_utf8(out.stdout).unwrap();
    for e in [
        "LENS: off (",
        "MOTION: off (",
        "SPECTRAL: off (",
        "MEDIA: off (",
        "TEXTURES: off (",
        "NORMAL_MAPS: off (",
    ] {
        assert!(s.contains(e), "{e} missing in\n{s}");
    }
    assert!(s.contains("kd-tree:"));
    assert!(
        s.contains("environment: Constant(Rgb(0.5, 0.5, 0.5))"),
        "{s}"
    );
}

#[test]
fn info_prints_lights_and_textures_in_scene_syntax() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let info = |scene: &str| {
        let out = prism()
            .args(["info", root.join(scene).to_str().unwrap()])
            .output()
            .unwrap();
        assert!(out.status.success());
        String::from_utf8(out.stdout).unwrap()
    };
    let s = info("scenes/textures.ron");
    assert!(
        s.contains("texture: (albedo: Bricks(brick: Rgb(0.5, 0.15, 0.1), mortar: Rgb(0.8, 0.8, 0.75), size: (0.4, 0.2)"),
        "{s}"
    );
    let s = info("scenes/god_rays.ron");
    assert!(
        s.contains("\"spot\": light: Spot(position: (-2.5, 4.6, -1.5)"),
        "{s}"
    );
}

#[test]
fn syntax_error_names_file_line_and_column() {
    let d = tempfile::tempdir().unwrap();
    let scene = write(d.path(), "bad.ron", &GOOD.replace("spp: 2)", "spp: 2"));
    let err = fails(&["render", scene.to_str().unwrap()]);
    assert!(err.contains("bad.ron:"), "{err}");
    assert!(
        err.split(':')
            .nth(2)
            .is_some_and(|l| l.trim().parse::<u32>().is_ok()),
        "{err}"
    );
}

#[test]
fn unknown_field_is_refused_with_its_name() {
    let d = tempfile::tempdir().unwrap();
    let scene = write(
        d.path(),
        "s.ron",
        &GOOD.replace("radius: 1.0", "radius: 1.0, colour: 3"),
    );
    let err = fails(&["render", scene.to_str().unwrap()]);
    assert!(err.contains("s.ron:6:"), "{err}");
    assert!(err.contains("colour"), "{err}");
    assert!(err.contains("entity \"ball\""), "{err}");
}

#[test]
fn negative_radius_names_entity_field_and_range() {
    let d = tempfile::tempdir().unwrap();
    let scene = write(
        d.path(),
        "s.ron",
        &GOOD.replace("radius: 1.0", "radius: -1.0"),
    );
    let err = fails(&["render", scene.to_str().unwrap()]);
    assert!(err.contains("s.ron:6:"), "{err}");
    assert!(err.contains("entity \"ball\""), "{err}");
    assert!(err.contains("radius"), "{err}");
    assert!(err.contains("> 0"), "{err}");
}

#[test]
fn refusals_say_what_to_write_instead() {
    let d = tempfile::tempdir().unwrap();
    // A colour written as a bare tuple: RON alone says only "Expected identifier".
    let scene = write(
        d.path(),
        "t.ron",
        &GOOD.replace("albedo: Rgb(0.5, 0.5, 0.5)", "albedo: (0.5, 0.5, 0.5)"),
    );
    let err = fails(&["info", scene.to_str().unwrap()]);
    assert!(
        err.contains("t.ron:7:") && err.contains("Rgb(0.8, 0.3, 0.2)"),
        "{err}"
    );
    // Two or three wavelengths would carry four.
    let scene = write(
        d.path(),
        "w.ron",
        &GOOD.replace("spp: 2)", "spp: 2, integrator: (wavelengths: 3))"),
    );
    let err = fails(&["info", scene.to_str().unwrap()]);
    assert!(err.contains("w.ron:2:") && err.contains("1 or 4"), "{err}");
    // A point light's motion would be ignored, so it is refused.
    let scene = write(
        d.path(),
        "p.ron",
        &GOOD.replace(
            "    ],",
            "        (name: \"bulb\", light: Point(position: (0.0, 2.0, 0.0), intensity: Rgb(1.0, 1.0, 1.0)),\n         motion: (velocity: (1.0, 0.0, 0.0))),\n    ],",
        ),
    );
    let err = fails(&["info", scene.to_str().unwrap()]);
    assert!(err.contains("\"bulb\"") && err.contains("motion"), "{err}");
}

#[test]
fn zero_size_image_is_refused() {
    let d = tempfile::tempdir().unwrap();
    let scene = write(d.path(), "s.ron", &GOOD.replace("width: 8", "width: 0"));
    let err = fails(&["render", scene.to_str().unwrap()]);
    assert!(err.contains("s.ron:2:") && err.contains("width"), "{err}");
    let good = write(d.path(), "g.ron", GOOD);
    let err = fails(&["render", good.to_str().unwrap(), "--size", "0x10"]);
    assert!(err.contains("1..=65536"), "{err}");
}

#[test]
fn missing_scene_file_names_the_path() {
    let err = fails(&["render", "/nonexistent/scene.ron"]);
    assert!(err.contains("/nonexistent/scene.ron"), "{err}");
}

/// Hostile paths: a FIFO (which would block a reader forever), a device (`/dev/zero` never
/// ends) and a directory are refused by name, at once, as a scene and as a mesh.
#[cfg(unix)]
#[test]
fn non_regular_files_are_refused_without_reading_them() {
    let d = tempfile::tempdir().unwrap();
    let fifo = d.path().join("pipe.ron");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    assert!(made.is_ok_and(|s| s.success()), "mkfifo");
    let dir = d.path().join("folder.ron");
    std::fs::create_dir(&dir).unwrap();
    let started = std::time::Instant::now();
    for (path, why) in [
        (fifo.to_str().unwrap(), "not a regular file"),
        ("/dev/zero", "not a regular file"),
        (dir.to_str().unwrap(), "a directory"),
    ] {
        let err = fails(&["render", path]);
        assert!(err.contains(path) && err.contains(why), "{err}");
    }
    let obj = d.path().join("pipe.obj");
    let made = std::process::Command::new("mkfifo").arg(&obj).status();
    assert!(made.is_ok_and(|s| s.success()), "mkfifo");
    let mesh = write(
        d.path(),
        "mesh.ron",
        &GOOD.replace(
            "shape: Sphere(center: (0.0, 0.0, 0.0), radius: 1.0)",
            "shape: Mesh(path: \"pipe.obj\")",
        ),
    );
    let err = fails(&["render", mesh.to_str().unwrap()]);
    assert!(
        err.contains("pipe.obj") && err.contains("not a regular file"),
        "{err}"
    );
    // Nothing waited on the FIFO.
    assert!(started.elapsed().as_secs() < 60);
}

/// Sample and frame numbers are 32-bit: ranges that would wrap (and silently repeat samples
/// or render nothing) or list billions of frames are refused.
#[test]
fn the_film_size_is_bounded_before_it_is_allocated() {
    let d = tempfile::tempdir().unwrap();
    // 65536² wrapped the u32 pixel count to 0; 16384² is the largest film accepted.
    let big = write(
        d.path(),
        "big.ron",
        &GOOD.replace("width: 8, height: 6", "width: 65536, height: 65536"),
    );
    let err = fails(&["render", big.to_str().unwrap()]);
    assert!(
        err.contains("big.ron:2:")
            && err.contains("4294967296 pixels")
            && err.contains("268435456"),
        "{err}"
    );
    let good = write(d.path(), "g.ron", GOOD);
    let g = good.to_str().unwrap();
    let err = fails(&["render", g, "--size", "16385x16384"]);
    assert!(
        err.contains("16385 × 16384") && err.contains("268435456"),
        "{err}"
    );
    let err = fails(&[
        "render",
        g,
        "--set",
        "render.width=65536",
        "--set",
        "render.height=5000",
    ]);
    assert!(
        err.contains("--set render.height") && err.contains("268435456"),
        "{err}"
    );
    // Within the bound, nothing is refused (a thin strip, to stay fast).
    let out = prism()
        .args([
            "render", g, "--quiet", "--spp", "1", "--size", "65536x1", "-o",
        ])
        .arg(d.path().join("strip.exr"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn checks_of_several_fields_name_the_field_at_fault() {
    let d = tempfile::tempdir().unwrap();
    // These checks run when their group closes, after its last field, which the message
    // named instead (`g` for a negative sigma_a, `radius` for a zero normal).
    for (from, to, field) in [
        (
            "material: Diffuse(albedo: Rgb(0.5, 0.5, 0.5))",
            "medium: (sigma_a: Rgb(-1.0, 0.0, 0.0), sigma_s: Rgb(0.1, 0.1, 0.1), g: 0.3)",
            "field `sigma_a`",
        ),
        (
            "shape: Sphere(center: (0.0, 0.0, 0.0), radius: 1.0)",
            "shape: Disk(center: (0.0, 0.0, 0.0), normal: (0.0, 0.0, 0.0), radius: 1.0)",
            "field `normal`",
        ),
        (
            "material: Diffuse(albedo: Rgb(0.5, 0.5, 0.5))",
            "material: Light(emission: Blackbody(kelvin: 6500.0, scale: -1.0))",
            "field `scale`",
        ),
    ] {
        let scene = write(d.path(), "f.ron", &GOOD.replace(from, to));
        let err = fails(&["render", scene.to_str().unwrap()]);
        assert!(
            err.contains("f.ron:") && err.contains("entity \"ball\"") && err.contains(field),
            "{err}"
        );
        assert_eq!(err.matches("field `").count(), 1, "{err}");
    }
}

#[test]
fn asset_paths_stay_inside_the_asset_root_unless_allowed() {
    let d = tempfile::tempdir().unwrap();
    let scenes = d.path().join("project/scenes");
    std::fs::create_dir_all(&scenes).unwrap();
    // Any readable file would do: the path is refused before anything reads it.
    let secret = d.path().join("secret.png");
    std::fs::write(&secret, b"not an image").unwrap();
    let textured = |path: &str| {
        GOOD.replace(
            "material: Diffuse(albedo: Rgb(0.5, 0.5, 0.5))",
            &format!(
                "material: Diffuse(albedo: Rgb(0.5, 0.5, 0.5)), texture: (albedo: Image(path: {path:?}))"
            ),
        )
    };
    let climbs = write(&scenes, "climbs.ron", &textured("../../secret.png"));
    let err = fails(&["render", climbs.to_str().unwrap()]);
    assert!(
        err.contains("climbs.ron")
            && err.contains("entity \"ball\"")
            && err.contains("outside the asset root"),
        "{err}"
    );
    let absolute = write(&scenes, "abs.ron", &textured(secret.to_str().unwrap()));
    let err = fails(&["render", absolute.to_str().unwrap()]);
    assert!(err.contains("absolute asset path"), "{err}");
    // Lifted, or moved to include the file, the check passes and the image is read (and
    // refused as an image, which shows the path got through).
    for extra in [
        vec!["--allow-any-path".to_string()],
        vec![
            "--asset-root".to_string(),
            d.path().to_str().unwrap().to_string(),
        ],
    ] {
        let mut args = vec!["render".to_string(), climbs.to_str().unwrap().to_string()];
        args.extend(extra);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let err = fails(&args);
        assert!(
            !err.contains("asset root") && err.contains("secret.png"),
            "{err}"
        );
    }
    let err = fails(&[
        "render",
        climbs.to_str().unwrap(),
        "--asset-root",
        "/nonexistent/dir",
    ]);
    assert!(
        err.contains("--asset-root") && err.contains("not a folder"),
        "{err}"
    );
}

#[test]
fn negative_exposure_is_a_value_and_a_non_finite_one_is_refused() {
    let d = tempfile::tempdir().unwrap();
    let good = write(d.path(), "g.ron", GOOD);
    let out = d.path().join("dark.png");
    let run = prism()
        .args([
            "render",
            good.to_str().unwrap(),
            "--quiet",
            "--exposure",
            "-1",
            "-o",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(out.exists());
    let err = fails(&["render", good.to_str().unwrap(), "--exposure", "nan"]);
    assert!(err.contains("-100..=100"), "{err}");
}

#[test]
fn names_are_escaped_and_cut_in_messages() {
    let d = tempfile::tempdir().unwrap();
    // An escape sequence in a name must not reach the terminal, and a long name must not
    // make a long line.
    let long = "x".repeat(100_000);
    for (name, shown) in [
        ("evil\u{1b}[31mred", "evil\\u{1b}[31mred"),
        (long.as_str(), "(100000 characters)"),
    ] {
        let scene = write(
            d.path(),
            "n.ron",
            &GOOD
                .replace("name: \"ball\"", &format!("name: \"{name}\""))
                .replace("radius: 1.0", "radius: -1.0"),
        );
        let err = fails(&["render", scene.to_str().unwrap()]);
        assert!(!err.contains('\u{1b}'), "{err:?}");
        assert!(err.contains(shown), "{err:?}");
        assert!(err.len() < 400, "{} bytes", err.len());
    }
}

#[test]
fn sample_and_frame_ranges_cannot_wrap() {
    let d = tempfile::tempdir().unwrap();
    let scene = write(d.path(), "s.ron", GOOD);
    let s = scene.to_str().unwrap();
    let err = fails(&["render", s, "--sample-offset", "4294967295", "--spp", "2"]);
    assert!(
        err.contains("--sample-offset 4294967295 with 2 samples"),
        "{err}"
    );
    let err = fails(&["render", s, "--frames", "0..=4294967295"]);
    assert!(err.contains("out of range"), "{err}");
    let err = fails(&["render", s, "--frames", "0..4294967295"]);
    assert!(err.contains("at most 1000000"), "{err}");
    // Starting 100,000 threads took most of a minute to fail; a path in a closed mirror with
    // max_depth 4294967295 never ended.
    let err = fails(&["render", s, "--threads", "100000"]);
    assert!(
        err.contains("--threads must be in 1..=1024, got 100000"),
        "{err}"
    );
    let deep = write(
        d.path(),
        "deep.ron",
        &GOOD.replace("spp: 2)", "spp: 2, max_depth: 4294967295)"),
    );
    let err = fails(&["render", deep.to_str().unwrap()]);
    assert!(
        err.contains("deep.ron:2:") && err.contains("at most 1024 scattering events"),
        "{err}"
    );
}

/// The hostile files of the hardening list, through the binary: each refused with one line
/// naming the file and what it claims, before anything is allocated for it.
#[test]
fn files_claiming_huge_sizes_are_refused_by_the_commands() {
    let d = tempfile::tempdir().unwrap();
    let scenes = d.path().join("scenes");
    std::fs::create_dir_all(&scenes).unwrap();
    let with_entity = |name: &str, entity: &str| {
        write(
            &scenes,
            name,
            &GOOD.replace("    ],\n)", &format!("        {entity},\n    ],\n)")),
        )
    };
    // PLY headers claiming 2⁶⁴ − 1 and 10¹¹ vertices (a panic and an abort, once).
    for (file, count, format) in [
        ("huge.ply", "18446744073709551615", "ascii"),
        ("big.ply", "100000000000", "binary_little_endian"),
    ] {
        write(
            &scenes,
            file,
            &format!(
                "ply\nformat {format} 1.0\nelement vertex {count}\nproperty float x\n\
                 property float y\nproperty float z\nend_header\n0 0 0\n"
            ),
        );
        let scene = with_entity(
            "m.ron",
            &format!(
                "(name: \"m\", shape: Mesh(path: \"{file}\"), material: Diffuse(albedo: \
                 Rgb(0.5, 0.5, 0.5)))"
            ),
        );
        let err = fails(&["render", scene.to_str().unwrap()]);
        assert!(
            err.contains(file) && err.contains(&format!("claims {count}")),
            "{err}"
        );
    }
    // An EXR whose data window claims 200000 × 200000: compare and merge refuse it.
    let exr = d.path().join("huge.exr");
    let meta = prism::film::ImageMeta {
        spp: 1,
        sample_offset: 0,
        scene_hash: 0,
        simd: None,
        complete: true,
        settings: None,
    };
    prism::film::write_image(
        &exr,
        &prism::film::Image::filled(1, 1, [0.5; 3]),
        &meta,
        &prism::film::PngOptions::default(),
    )
    .unwrap();
    let mut bytes = std::fs::read(&exr).unwrap();
    let key = b"dataWindow\0box2i\0";
    let at = bytes.windows(key.len()).position(|w| w == key).unwrap() + key.len() + 4;
    for k in [2, 3] {
        bytes[at + 4 * k..at + 4 * k + 4].copy_from_slice(&199_999i32.to_le_bytes());
    }
    std::fs::write(&exr, &bytes).unwrap();
    let e = exr.to_str().unwrap();
    for args in [
        vec!["compare", e, e],
        vec![
            "merge",
            e,
            e,
            "-o",
            d.path().join("m.exr").to_str().unwrap(),
        ],
    ] {
        let err = fails(&args);
        assert!(
            err.contains("huge.exr") && err.contains("200000×200000"),
            "{args:?}: {err}"
        );
    }
    // A 22000 × 22000 all-zero PNG as a texture: it passed the decoder's own limit and then
    // aborted in the conversion to f32 RGB (12 bytes per pixel).
    // (Its header is what matters: the file here stops after it.)
    let png = scenes.join("zero.png");
    let mut enc = png::Encoder::new(std::fs::File::create(&png).unwrap(), 22_000, 22_000);
    enc.set_color(png::ColorType::Grayscale);
    let mut w = enc.write_header().unwrap();
    // An empty data chunk: decoders read the header up to the first one.
    w.write_chunk(png::chunk::IDAT, &[]).unwrap();
    drop(w);
    let scene = with_entity(
        "t.ron",
        "(name: \"t\", shape: Rect(center: (0.0, 0.0, -2.0), u: (1.0, 0.0, 0.0), v: (0.0, 1.0, 0.0)), \
         material: Diffuse(albedo: Rgb(0.5, 0.5, 0.5)), texture: (albedo: Image(path: \"zero.png\")))",
    );
    let err = fails(&["render", scene.to_str().unwrap()]);
    assert!(err.contains("zero.png") && err.contains("22000"), "{err}");
}

#[test]
fn integers_too_large_for_their_type_are_refused_with_the_range() {
    let d = tempfile::tempdir().unwrap();
    for (from, to, want) in [
        (
            "spp: 2)",
            "spp: 99999999999)",
            "field `spp`: the number is out of range: must be in 1..=4294967295",
        ),
        (
            "spp: 2)",
            "spp: 2, seed: -1)",
            "field `seed`: the number is out of range: must be in 0..=18446744073709551615",
        ),
        (
            "width: 8,",
            "width: -8,",
            "field `width`: the number is out of range: must be in 1..=65536 pixels",
        ),
    ] {
        let scene = write(d.path(), "s.ron", &GOOD.replace(from, to));
        let err = fails(&["render", scene.to_str().unwrap()]);
        assert!(
            err.starts_with("error: ") && err.contains("s.ron:2:") && err.contains(want),
            "{err}\nwanted: {want}"
        );
    }
}

/// Errors found after parsing carry the position of the value at fault, or of its entity
/// when the field is absent.
#[test]
fn errors_about_entities_after_parsing_carry_their_position() {
    let d = tempfile::tempdir().unwrap();
    let ball = "material: Diffuse(albedo: Rgb(0.5, 0.5, 0.5))";
    // Replace `from` by `to`; the error must point at the first `marker` and say `says`.
    let cases = [
        (
            ball,
            "material: Diffuse(albedo: Rgb(0.5, 0.5, 0.5)), light: Point(position: \
             (0.0, 0.0, 0.0), intensity: Rgb(1.0, 1.0, 1.0))",
            "Point(",
            "entity \"ball\": field `light`: a point or spot light has no shape or material",
        ),
        (
            "shape: Sphere(center: (0.0, 0.0, 0.0), radius: 1.0),\n         material: Diffuse(albedo: Rgb(0.5, 0.5, 0.5))",
            "shape: Box(min: (0.0, 0.0, 0.0), max: (1.0, 1.0, 1.0)),\n         material: Light(emission: Rgb(1.0, 1.0, 1.0))",
            "Light(",
            "entity \"ball\": field `material`: a Light needs a Sphere, Rect or Disk",
        ),
        (
            ", material: Diffuse(albedo: Rgb(0.5, 0.5, 0.5))",
            "",
            "(name: \"ball\"",
            "entity \"ball\": field `material`: a shape needs a material",
        ),
        (
            "look_at: (0.0, 0.0, 0.0)",
            "look_at: (0.0, 0.0, 4.0)",
            "(0.0, 0.0, 4.0)),",
            "entity \"camera\": field `look_at`:",
        ),
        (
            ball,
            "material: Conductor(metal: Au, alpha: 1.5)",
            "1.5)",
            "entity \"ball\": field `material.alpha`: must be in [0, 1], got 1.5",
        ),
        (
            ball,
            "material: Conductor(metal: Au, alpha: 0.1, roughness: 0.3)",
            "0.3)",
            "entity \"ball\": field `material.roughness`: give `alpha` or `roughness`",
        ),
        (
            ball,
            "material: Conductor(eta: Rgb(0.2, 0.0, 1.0), k: Rgb(3.0, 2.0, 1.0))",
            "Rgb(0.2, 0.0",
            "entity \"ball\": field `material.eta`: every channel must be in (0, 100], got Rgb(0.2, 0, 1)",
        ),
        (
            ball,
            "material: Conductor(eta: Rgb(0.2, 0.5, 1.0))",
            "Conductor(",
            "entity \"ball\": field `material.k`: `eta` needs `k` beside it",
        ),
        (
            ball,
            "material: Conductor(metal: Au, reflectance: Rgb(1.0, 1.0, 1.0))",
            "Conductor(",
            "entity \"ball\": field `material`: a Conductor takes one of",
        ),
        (
            ball,
            "material: Plastic(albedo: Rgb(0.5, 0.5, 0.5), ior: 3.5)",
            "3.5)",
            "entity \"ball\": field `material.ior`: must be in [1, 3], got 3.5",
        ),
        (
            ball,
            "material: Diffuse(albedo: Rgb(0.5, 0.5, 0.5)), texture: (roughness: Checker(a: 0.1, b: 0.2, size: 0.5))",
            "Checker(a: 0.1, b: 0.2",
            "entity \"ball\": field `texture.roughness`: a roughness texture needs a Conductor",
        ),
        (
            ball,
            "material: Diffuse(albedo: Rgb(0.5, 0.5, 0.5)), texture: (roughness: Checker(a: 0.1, b: 1.2, size: 0.5))",
            "1.2, size",
            "entity \"ball\": field `b`: must be in [0, 1], got 1.2",
        ),
        (
            ball,
            "material: Dielectric(ior: Constant(1.5), roughness: 1.2)",
            "1.2)",
            "entity \"ball\": field `material.roughness`: must be in [0, 1], got 1.2",
        ),
    ];
    for (from, to, marker, says) in cases {
        let text = GOOD.replace(",\n         material", ", material").replace(
            &from.replace(",\n         material", ", material"),
            &to.replace(",\n         material", ", material"),
        );
        assert_ne!(text, GOOD.replace(",\n         material", ", material"));
        let at = text.find(marker).unwrap();
        let line = text[..at].matches('\n').count() + 1;
        let col = at - text[..at].rfind('\n').map_or(0, |i| i + 1) + 1;
        let scene = write(d.path(), "s.ron", &text);
        let err = fails(&["render", scene.to_str().unwrap()]);
        let want = format!("s.ron:{line}:{col}: {says}");
        assert!(err.contains(&want), "{err}\nwanted: {want}\n{text}");
    }
}

#[test]
fn bad_values_are_refused_with_their_valid_range() {
    let d = tempfile::tempdir().unwrap();
    let with = |name: &str, material: &str| {
        write(
            d.path(),
            name,
            &GOOD.replace("material: Diffuse(albedo: Rgb(0.5, 0.5, 0.5))", material),
        )
    };
    // A Cauchy IOR below 1 somewhere in 360–830 nm.
    let scene = with(
        "c.ron",
        "material: Dielectric(ior: Cauchy(a: 0.9, b: 0.004))",
    );
    let err = fails(&["render", scene.to_str().unwrap()]);
    assert!(
        err.contains(">= 1") && err.contains("nm") && err.contains(":"),
        "{err}"
    );
    // A Sellmeier resonance at 500 nm, inside the simulated range.
    let scene = with(
        "s.ron",
        "material: Dielectric(ior: Sellmeier(b: (1.0, 0.0, 0.0), c: (0.25, 0.0, 0.0)))",
    );
    let err = fails(&["render", scene.to_str().unwrap()]);
    assert!(err.contains("resonance at 500 nm"), "{err}");
    let scene = with(
        "b.ron",
        "material: Light(emission: Blackbody(kelvin: 20.0, scale: 1.0))",
    );
    let err = fails(&["render", scene.to_str().unwrap()]);
    assert!(
        err.contains("field `kelvin`") && err.contains("500..=100000"),
        "{err}"
    );
    let scene = with("p.ron", "material: Dielectric(ior: Preset(Glass))");
    let err = fails(&["render", scene.to_str().unwrap()]);
    assert!(err.contains("Bk7") && err.contains("Diamond"), "{err}");
    let err = fails(&[
        "render",
        write(d.path(), "g.ron", GOOD).to_str().unwrap(),
        "--set",
        "render.nonsense=3",
    ]);
    assert!(err.contains("unknown key"), "{err}");
}

#[test]
fn set_overrides_a_value() {
    let d = tempfile::tempdir().unwrap();
    let scene = write(d.path(), "s.ron", GOOD);
    let out = d.path().join("o.exr");
    prism()
        .args([
            "render",
            scene.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--quiet",
            "--set",
            "render.spp=3",
        ])
        .assert()
        .success();
    assert_eq!(prism::film::read_image(&out).unwrap().1.unwrap().spp, 3);
    let err = fails(&[
        "render",
        scene.to_str().unwrap(),
        "--set",
        "render.integrator.fresnel=Wrong",
    ]);
    assert!(err.contains("render.integrator.fresnel"), "{err}");
}

#[test]
fn set_reaches_entity_fields_by_name_and_index() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let cornell = root.join("scenes/cornell.ron");
    let out = prism()
        .args([
            "info",
            cornell.to_str().unwrap(),
            "--set",
            r#"entities["red wall"].material.albedo=Rgb(0.1, 0.2, 0.9)"#,
            "--set",
            "entities[0].material=Light(emission: Rgb(30.0, 30.0, 30.0))",
        ])
        .assert()
        .success();
    let text = String::from_utf8(out.get_output().stdout.clone()).unwrap();
    assert!(
        text.contains("\"red wall\": Rect, Diffuse(albedo: Rgb(0.1, 0.2, 0.9))"),
        "{text}"
    );
    assert!(
        text.contains("\"light\": Rect, Light(emission: Rgb(30.0, 30.0, 30.0))"),
        "{text}"
    );
    // The value is checked as the file's own, and the error names the --set.
    let err = fails(&[
        "info",
        cornell.to_str().unwrap(),
        "--set",
        r#"entities["red wall"].material.albedo=Rgb(0.1, 0.1, 1.9)"#,
    ]);
    assert!(
        err.contains(r#"--set entities["red wall"].material.albedo"#) && err.contains("[0, 1]"),
        "{err}"
    );
    let err = fails(&[
        "info",
        cornell.to_str().unwrap(),
        "--set",
        "entities[99].material=Mirror",
    ]);
    assert!(
        err.contains("entities[99] does not exist: the file has 8 entities"),
        "{err}"
    );
    // A field added to a material that has no such field is the --set's fault, not the file's.
    let err = fails(&[
        "info",
        cornell.to_str().unwrap(),
        "--set",
        r#"entities["light"].material.albedo=Rgb(0.5, 0.5, 0.5)"#,
    ]);
    assert!(
        err.contains(r#"--set entities["light"].material.albedo"#) && err.contains("albedo"),
        "{err}"
    );
}

#[test]
fn the_readme_scene_example_loads() {
    // The README's scene is the schema's showcase: it must stay a valid scene.
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let start = readme.find("```ron\n").expect("a ron block") + 7;
    let end = start + readme[start..].find("```").unwrap();
    let scene =
        prism::scene_file::load_str(&readme[start..end], &root.join("scenes/readme.ron"), &[]);
    assert!(scene.is_ok(), "{}", scene.err().unwrap());
}

#[test]
fn a_missing_scene_is_named() {
    let err = fails(&["render"]);
    assert!(err.contains("<SCENE>"), "{err}");
}

#[test]
fn a_misspelt_flag_keeps_clap_suggestion() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write(dir.path(), "s.ron", GOOD);
    let err = fails(&["render", scene.to_str().unwrap(), "--sp", "4"]);
    assert!(err.contains("'--sp'") && err.contains("'--spp'"), "{err}");
}

#[test]
fn bare_prism_prints_the_help_and_exits_2() {
    let out = prism().output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let text = String::from_utf8(out.stderr).unwrap() + &String::from_utf8(out.stdout).unwrap();
    assert!(
        text.contains("Usage: prism") && text.contains("render"),
        "{text}"
    );
}

#[test]
fn t_is_short_for_threads() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write(dir.path(), "s.ron", GOOD);
    let out = dir.path().join("o.png");
    prism()
        .args([
            "render",
            scene.to_str().unwrap(),
            "-t",
            "1",
            "--quiet",
            "-o",
        ])
        .arg(&out)
        .assert()
        .success();
    assert!(out.exists());
}

#[test]
fn a_scene_without_light_warns_and_one_with_light_does_not() {
    let d = tempfile::tempdir().unwrap();
    let dark = GOOD.replace("    environment: Constant(Rgb(0.5, 0.5, 0.5)),\n", "");
    assert_ne!(dark, GOOD);
    let dark = write(d.path(), "dark.ron", &dark);
    let lit = write(d.path(), "lit.ron", GOOD);
    let run = |scene: &Path, quiet: bool| {
        let mut c = prism();
        c.args(["render", scene.to_str().unwrap(), "-o"])
            .arg(d.path().join("o.png"));
        if quiet {
            c.arg("--quiet");
        }
        let out = c.output().unwrap();
        assert!(out.status.success());
        String::from_utf8(out.stderr).unwrap()
    };
    let err = run(&dark, false);
    assert_eq!(
        err.matches("warning: the scene has no light").count(),
        1,
        "{err}"
    );
    assert!(
        !run(&dark, true).contains("warning"),
        "--quiet hides warnings"
    );
    assert!(!run(&lit, false).contains("warning"));
    let info = prism()
        .args(["info", dark.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(
        String::from_utf8(info.stdout)
            .unwrap()
            .contains("warning: the scene has no light")
    );
}

#[test]
fn a_light_with_zero_emission_is_named() {
    let d = tempfile::tempdir().unwrap();
    let scene = GOOD.replace(
        "    ],\n)",
        "        (name: \"dead lamp\", shape: Sphere(center: (0.0, 3.0, 0.0), radius: 0.5),\n         material: Light(emission: Rgb(0.0, 0.0, 0.0))),\n    ],\n)",
    );
    assert_ne!(scene, GOOD);
    let scene = write(d.path(), "s.ron", &scene);
    let out = prism()
        .args(["render", scene.to_str().unwrap(), "-o"])
        .arg(d.path().join("o.png"))
        .output()
        .unwrap();
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(
        err.contains("warning: entity \"dead lamp\": a Light with zero emission"),
        "{err}"
    );
}

#[test]
fn a_lamp_facing_away_from_everything_is_warned_of() {
    let d = tempfile::tempdir().unwrap();
    // A rectangle above the ball; its normal u × v is +y (away from the ball and the camera)
    // or -y (towards the ball).
    let lamp = |v: &str| {
        GOOD.replace(
            "    ],\n)",
            &format!(
                "        (name: \"lamp\", shape: Rect(center: (0.0, 3.0, 0.0), u: (0.5, 0.0, 0.0), v: {v}),\n         material: Light(emission: Rgb(5.0, 5.0, 5.0))),\n    ],\n)"
            ),
        )
    };
    let info = |text: &str, name: &str| {
        let scene = write(d.path(), name, text);
        let out = prism()
            .args(["info", scene.to_str().unwrap()])
            .output()
            .unwrap();
        String::from_utf8(out.stdout).unwrap()
    };
    let away = info(&lamp("(0.0, 0.0, -0.5)"), "away.ron");
    assert!(
        away.contains(
            "warning: entity \"lamp\": a one-sided Light whose front faces no other entity"
        ),
        "{away}"
    );
    let down = info(&lamp("(0.0, 0.0, 0.5)"), "down.ron");
    assert!(!down.contains("warning"), "{down}");
}

#[test]
fn a_camera_inside_an_opaque_shape_is_warned_of() {
    let d = tempfile::tempdir().unwrap();
    let inside = GOOD.replace("position: (0.0, 0.0, 4.0)", "position: (0.0, 0.0, 0.5)");
    assert_ne!(inside, GOOD);
    let inside = write(d.path(), "inside.ron", &inside);
    let out = prism()
        .args(["info", inside.to_str().unwrap()])
        .output()
        .unwrap();
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.contains("warning: the camera is inside entity \"ball\""),
        "{text}"
    );
    let outside = write(d.path(), "outside.ron", GOOD);
    let out = prism()
        .args(["info", outside.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!String::from_utf8(out.stdout).unwrap().contains("warning"));
}

#[test]
fn docs_cli_names_every_option_and_set_key() {
    use clap::CommandFactory;
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let doc = std::fs::read_to_string(root.join("docs/cli.md")).unwrap();
    for key in prism::scene_file::load::OVERRIDE_KEYS {
        assert!(
            doc.contains(&format!("`{key}`")),
            "docs/cli.md lacks --set key {key}"
        );
    }
    let cli = prism::cli::Cli::command();
    for sub in cli.get_subcommands() {
        assert!(
            doc.contains(&format!("`prism {}", sub.get_name())),
            "docs/cli.md lacks a section for prism {}",
            sub.get_name()
        );
        for arg in sub.get_arguments().filter(|a| !a.is_hide_set()) {
            if let Some(long) = arg.get_long() {
                assert!(
                    doc.contains(&format!("--{long}")),
                    "docs/cli.md lacks prism {} --{long}",
                    sub.get_name()
                );
            }
        }
    }
}

/// An anisotropic roughness runs along ∂p/∂u: a mesh without UVs has none, and is refused at
/// the roughness, with its position; the same mesh with UVs renders.
#[test]
fn anisotropy_needs_uvs_on_a_mesh() {
    let d = tempfile::tempdir().unwrap();
    let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    write(d.path(), "bare.obj", &format!("{tri}f 1 2 3\n"));
    write(
        d.path(),
        "uv.obj",
        &format!("{tri}vt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n"),
    );
    let scene = |mesh: &str| {
        GOOD.replace(
            "shape: Sphere(center: (0.0, 0.0, 0.0), radius: 1.0),\n         material: Diffuse(albedo: Rgb(0.5, 0.5, 0.5))",
            &format!(
                "shape: Mesh(path: \"{mesh}\"), material: Conductor(metal: Ni, alpha: (0.05, 0.4))"
            ),
        )
    };
    let text = scene("bare.obj");
    let at = text.find("(0.05").unwrap();
    let line = text[..at].matches('\n').count() + 1;
    let col = at - text[..at].rfind('\n').map_or(0, |i| i + 1) + 1;
    let bad = write(d.path(), "bare.ron", &text);
    let err = fails(&["render", bad.to_str().unwrap()]);
    let want = format!("bare.ron:{line}:{col}: entity \"ball\": field `material.alpha`");
    assert!(
        err.contains(&want) && err.contains("no UVs"),
        "{err}\nwanted: {want}"
    );
    let good = write(d.path(), "uv.ron", &scene("uv.obj"));
    let out = prism()
        .args(["render", good.to_str().unwrap(), "--quiet", "-o"])
        .arg(d.path().join("uv.png"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}
