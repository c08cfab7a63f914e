//! Our VTK files as VTK and ParaView read them: every kind of file sc-export and
//! sc-check write, opened with VTK's own reader (`tests/py/check_vtk.py`, the `vtk`
//! package in the test venv) and checked array by array against the stage files; and
//! a shipped result loaded, stepped through, warped and coloured by ParaView itself
//! (`docs/scripts/render.py` under `xvfb-run -a pvbatch`), its screenshot checked not
//! blank (`tests/py/check_png.py`).

use std::path::{Path, PathBuf};
use std::process::Command;

use splinecontact::format::scres::Results;

use crate::common::{python_script, repo, run, stderr, staged_pipeline};

/// Run the shipped `pipelines/<name>.yaml` in a scratch copy; its `out/` folder.
fn pipeline_out(name: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = staged_pipeline(name, &[&format!("{name}.msh")]);
    let o = run("sc-pipeline", &["-q", &format!("pipelines/{name}.yaml")], dir.path());
    assert!(o.status.success(), "{name}: {}", stderr(&o));
    let out = dir.path().join("pipelines/out");
    (dir, out)
}

/// `check_vtk.py <what> <file> <reference>`: its JSON summary.
fn check_vtk(what: &str, file: &Path, reference: &Path) -> serde_yaml::Value {
    let o = python_script("check_vtk.py", &[Path::new(what), file, reference]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "VTK's reader on {}: {}{}", file.display(), out, String::from_utf8_lossy(&o.stderr));
    serde_yaml::from_str(out.lines().last().unwrap_or("")).expect("one JSON line")
}

fn f64s(v: &serde_yaml::Value) -> Vec<f64> {
    v.as_sequence().expect("a list").iter().map(|x| x.as_f64().unwrap()).collect()
}

/// Per step of a results series (the undeformed state first): the load factor, the
/// largest |u| and the largest contact pressure (−t_N summed over pairs per node).
fn steps(r: &Results) -> Vec<(f64, f64, f64)> {
    let mut out = vec![(0.0, 0.0, 0.0)];
    for inc in &r.increments {
        let u = inc.u.iter().map(|u| (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt()).fold(0.0, f64::max);
        let mut p = vec![0.0; r.mesh.nodes.len()];
        for (pair, states) in r.pairs.iter().zip(&inc.contact) {
            for (&n, s) in pair.slave_nodes.iter().zip(states) {
                p[n as usize] -= s[1];
            }
        }
        out.push((inc.info.load_factor, u, p.iter().copied().fold(0.0, f64::max)));
    }
    out
}

/// The Parisch pipeline writes every kind of VTK file: the mesh, the contact model
/// (mesh, master surface, control net), the pre-solve check's point cloud, the
/// results series and the deformed master surface's series. VTK's reader opens each,
/// and every array has its documented name, type and size and our values (bit for
/// bit; averaged stresses to 1e-12).
#[test]
fn vtk_reads_every_file_of_the_parisch_pipeline() {
    let (_dir, out) = pipeline_out("parisch");
    let mesh = check_vtk("mesh", &out.join("parisch.vtu"), &out.join("parisch.scmesh"));
    assert_eq!((mesh["points"].as_u64(), mesh["hexes"].as_u64()), (Some(50), Some(13)), "{mesh:?}");
    let model = check_vtk("contact", &out.join("parisch_contact.vtu"), &out.join("parisch.sccontact"));
    let pair = &model["pairs"][0];
    assert_eq!(f64s(&pair["net"]), [4.0, 4.0], "{model:?}");
    // 3 × 3 spans of a biquadratic patch over a 4 × 4 net, 8 × 8 quads each; 24 net lines
    assert_eq!((pair["surface_quads"].as_u64(), pair["net_lines"].as_u64()), (Some(256), Some(24)), "{model:?}");
    assert!(f64s(&pair["mean_normal"])[2] > 0.999, "the master's normal points up, out of the lower block: {model:?}");
    let check = check_vtk("check", &out.join("parisch-check.vtu"), &out.join("parisch-check.csv"));
    assert_eq!(check["points"].as_u64(), Some(9), "{check:?}");
    let res = check_vtk("results", &out.join("parisch.pvd"), &out.join("parisch.scres"));
    let r = Results::read(&out.join("parisch.scres")).unwrap();
    let s = steps(&r);
    assert_eq!(f64s(&res["times"]), s.iter().map(|s| s.0).collect::<Vec<_>>());
    assert_eq!(res["active"].as_u64(), Some(9), "{res:?}");
    assert_eq!(res["max_contact_pressure"].as_f64(), Some(s[1].2), "{res:?}");
    assert_eq!(res["surfaces"][0]["steps"].as_u64(), Some(2), "{res:?}");
}

/// The frictional crossed beams (three increments): the series with the friction
/// arrays, read by VTK's reader and checked against the results file step by step.
#[test]
fn vtk_reads_the_frictional_crossed_beams_series() {
    let (_dir, out) = pipeline_out("crossed_beams");
    let res = check_vtk("results", &out.join("crossed_beams.pvd"), &out.join("crossed_beams.scres"));
    let r = Results::read(&out.join("crossed_beams.scres")).unwrap();
    let s = steps(&r);
    assert_eq!(res["frictional"].as_bool(), Some(true), "{res:?}");
    assert_eq!(f64s(&res["times"]), s.iter().map(|s| s.0).collect::<Vec<_>>());
    assert_eq!(res["steps"].as_u64(), Some(4));
    assert_eq!(res["max_contact_pressure"].as_f64(), Some(s[3].2), "{res:?}");
    assert_eq!(res["surfaces"][0]["steps"].as_u64(), Some(4), "{res:?}");
    let model = check_vtk("contact", &out.join("crossed_beams_contact.vtu"), &out.join("crossed_beams.sccontact"));
    assert_eq!(f64s(&model["pairs"][0]["net"]), [3.0, 16.0], "{model:?}");
}

/// The facet master (curved pad, `pipelines/curved-facet.yaml`): its tessellated
/// surface goes through every node of the net, in the model and in each step of the
/// deformed series.
#[test]
fn vtk_reads_the_facet_master_files() {
    let dir = staged_pipeline("curved-facet", &["curved-nby3.msh"]);
    let o = run("sc-pipeline", &["-q", "pipelines/curved-facet.yaml"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let out = dir.path().join("pipelines/out");
    let o = run("sc-export", &["-q", "curved-facet.sccontact", "-o", "curved-facet.vtu"], &out);
    assert!(o.status.success(), "{}", stderr(&o));
    let model = check_vtk("contact", &out.join("curved-facet.vtu"), &out.join("curved-facet.sccontact"));
    // a 7 × 4 net: 6 × 3 facets of 8 × 8 quads
    assert_eq!(model["pairs"][0]["surface_quads"].as_u64(), Some(6 * 3 * 64), "{model:?}");
    let res = check_vtk("results", &out.join("curved-facet.pvd"), &out.join("curved-facet.scres"));
    assert_eq!(res["steps"].as_u64(), Some(6), "{res:?}");
    assert_eq!(res["surfaces"][0]["steps"].as_u64(), Some(6), "{res:?}");
}

fn on_path(exe: &str) -> bool {
    std::env::var_os("PATH").is_some_and(|p| std::env::split_paths(&p).any(|d| d.join(exe).is_file()))
}

/// ParaView itself (Debian's `paraview` and `python3-paraview`, headless under
/// `xvfb-run`): `docs/scripts/render.py` loads the crossed beams' series with
/// ParaView's PVD reader, steps through every time step, warps by the displacement
/// and colours by contact pressure, then by von Mises stress, and saves 800 × 600
/// screenshots. What ParaView read in each step equals the results file (load
/// factor, largest |u|, largest pressure), and the pictures are pictures: many
/// colours, the bodies on a tenth of the image, the colour map's hues present.
/// Without pvbatch or xvfb-run this fails, unless SC_SKIP_PARAVIEW is set (test.sh
/// sets it, and says so loudly, when it cannot install ParaView).
#[test]
fn paraview_renders_the_crossed_beams() {
    if !(on_path("pvbatch") && on_path("xvfb-run")) {
        if std::env::var_os("SC_SKIP_PARAVIEW").is_some() {
            eprintln!("SKIPPED: pvbatch or xvfb-run missing and SC_SKIP_PARAVIEW set");
            return;
        }
        panic!("pvbatch or xvfb-run missing: apt-get install paraview python3-paraview xvfb xauth (./test.sh does, as root)");
    }
    let (_dir, out) = pipeline_out("crossed_beams");
    let r = Results::read(&out.join("crossed_beams.scres")).unwrap();
    let s = steps(&r);
    for (field, coloured) in [("contact_pressure", 0.002), ("von_mises", 0.05)] {
        let png = out.join(format!("{field}.png"));
        // xvfb-run -a starts looking for a free display at :99, and two runs started
        // together (two checkouts testing on one machine) race for it ("bad X server
        // connection"): start from a display number of our own, and try again if the
        // X server still did not come up
        let render = |attempt: u32| {
            let display = (100 + (std::process::id() % 400) * 2 + attempt * 800).to_string();
            Command::new("xvfb-run")
                .args(["-a", "-n", &display, "pvbatch"])
                .arg(repo().join("docs/scripts/render.py"))
                .arg(out.join("crossed_beams.pvd"))
                .arg("-o")
                .arg(&png)
                .args(["--field", field])
                .output()
                .expect("xvfb-run runs")
        };
        let mut o = render(0);
        for attempt in 1..3 {
            if o.status.success() || !String::from_utf8_lossy(&o.stderr).contains("X server") {
                break;
            }
            o = render(attempt);
        }
        let stdout = String::from_utf8_lossy(&o.stdout);
        assert!(o.status.success(), "render.py --field {field}: {stdout}{}", String::from_utf8_lossy(&o.stderr));
        let line = stdout.lines().rev().find(|l| l.starts_with('{')).expect("render.py's JSON line");
        let j: serde_yaml::Value = serde_yaml::from_str(line).unwrap();
        assert_eq!(f64s(&j["times"]), s.iter().map(|s| s.0).collect::<Vec<_>>(), "{line}");
        let seen = j["steps"].as_sequence().unwrap();
        assert_eq!(seen.len(), 4);
        for (k, (step, (_, u, p))) in seen.iter().zip(&s).enumerate() {
            assert_eq!(step["points"].as_u64(), Some(288), "{line}");
            let pu = step["max_u"].as_f64().unwrap();
            assert!((pu - u).abs() <= 1e-12 * u, "step {k}: ParaView's max |u| {pu}, ours {u}");
            if field == "contact_pressure" {
                assert_eq!(step["range"][1].as_f64(), Some(*p), "step {k}: {line}");
            }
        }
        assert_eq!(j["shown"].as_u64(), Some(3), "{line}");
        let o = python_script("check_png.py", &[&png]);
        let img = String::from_utf8_lossy(&o.stdout);
        assert!(o.status.success(), "{png:?}: {img}{}", String::from_utf8_lossy(&o.stderr));
        let img: serde_yaml::Value = serde_yaml::from_str(img.trim()).unwrap();
        assert_eq!((img["width"].as_u64(), img["height"].as_u64()), (Some(800), Some(600)), "{img:?}");
        assert!(img["distinct_colours"].as_u64().unwrap() > 200, "{field}: {img:?}");
        assert!(img["foreground"].as_f64().unwrap() > 0.08, "{field}: {img:?}");
        assert!(img["coloured"].as_f64().unwrap() > coloured, "{field}: {img:?}");
        let hues = f64s(&img["hue_fifths"]);
        assert!(hues.iter().filter(|&&h| h > 50.0).count() >= 3, "{field}: the colour map's hues {hues:?}");
    }
}
