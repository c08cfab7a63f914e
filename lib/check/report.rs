//! The check written three ways (`docs/formats.md`, "Pre-solve check"): a readable
//! summary, a CSV with one row per slave node of every pair, and a `.vtu` of the
//! slave nodes with the same fields as point data, so the culprits show in ParaView.
//! Files are written atomically (temporary file + rename), like every stage file.

use std::io::Write;
use std::path::Path;

use super::contact_check::{PairCheck, Projected};
use super::{CheckReport, VERSION};
use crate::format::setup::{Enforcement, Integration, MortarMultipliers, MortarQuadrature, MortarTransfer};
use crate::format::stage::{write_atomic, write_atomic_with, StageError};
use crate::format::vtk::{CellKind, Field, FieldValues, Grid, VtkError};

/// The CSV's columns, in order.
pub const CSV_COLUMNS: [&str; 18] =
    ["pair", "node_tag", "x", "y", "z", "projection", "reason", "g_n", "xi_1", "xi_2", "n_x", "n_y", "n_z", "penetrating", "behind", "adjust_move", "g_n_adjusted", "flag"];

fn range_text(r: Option<(f64, f64)>) -> String {
    match r {
        Some((lo, hi)) => format!("{lo:.4e} … {hi:.4e}"),
        None => "none".into(),
    }
}

fn pair_lines(p: &PairCheck, out: &mut Vec<String>) {
    let (inside, outside, failed) = p.counts();
    out.push(format!(
        "contact pair '{}': slave {}, master face set {} ({} [{}, {}], net: {})",
        p.name, p.slave, p.master, p.master_kind, p.orders[0], p.orders[1], p.net
    ));
    out.push(format!("  slave nodes           {}", p.rows.len()));
    let reasons = p.failures().iter().map(|(r, n)| format!("{n} {}", r.word())).collect::<Vec<_>>().join(", ");
    out.push(format!("  projection            {inside} inside, {outside} outside, {failed} failed{}", if failed > 0 { format!(" ({reasons})") } else { String::new() }));
    out.push(format!("  initial gap g_N       {} (nodes on the master; {} touching, |g_N| ≤ 1e-8 h)", range_text(p.gap_range()), p.touching()));
    match p.penetration_range() {
        Some((lo, hi, n)) => out.push(format!("  penetration −g_N      {n} nodes, {lo:.4e} … {hi:.4e}")),
        None => out.push("  penetration −g_N      none".into()),
    }
    let beyond = p.penetrating();
    let tags: Vec<String> = beyond.iter().take(20).map(|r| r.tag.to_string()).collect();
    out.push(format!(
        "  beyond tolerance      {} nodes (tolerance {:.3e}){}",
        beyond.len(),
        p.settings.penetration_tolerance,
        if beyond.is_empty() { String::new() } else { format!(": {}{}", tags.join(" "), if beyond.len() > 20 { " …" } else { "" }) }
    ));
    let o = &p.orientation;
    let verdict = if o.flipped() {
        if p.allow_flipped_master { "FLIPPED (allowed by allow_flipped_master)" } else { "FLIPPED: the solve refuses it" }
    } else if o.voters == 0 && o.cells == 0 {
        "undecided (no slave node on the master)"
    } else {
        "faces the slave body"
    };
    out.push(format!(
        "  master normal         {verdict}: {} of {} slave nodes on the master see it from behind; {} of {} master faces point into the master body",
        o.behind, o.voters, o.cells_inward, o.cells
    ));
    out.push(format!("  capture radius        {:.4e} (0.5 h; h = {:.4e}, the master net's mean edge; edge tolerance {:.3e})", p.capture, p.h_master, p.edge_tolerance));
    out.push(format!(
        "  penalty ε_N           {:e}{}, {}",
        p.settings.eps_n,
        if p.eps_n_default { " (default 25 G/h)" } else { " (setup)" },
        match p.settings.enforcement {
            Enforcement::Penalty => "penalty",
            Enforcement::AugmentedLagrangian => "augmented Lagrangian",
        }
    ));
    out.push(format!("  integration           {}", integration_text(p)));
    match &p.adjustment {
        None => out.push("  adjust                off".into()),
        Some(a) => {
            let largest = a.largest().map_or(String::new(), |m| {
                let tag = p.rows.iter().find(|r| r.node == m.node).map_or(m.node as u64, |r| r.tag);
                format!(", largest {:.4e} (node {tag})", m.g_n.abs())
            });
            out.push(format!("  adjust                {:e}: moves {} slave nodes onto the master{largest}", a.distance, a.moved.len()));
            let after = p.rows.iter().filter(|r| r.projected == Projected::Inside && r.adjust_move > 0.0).map(|r| r.g_n_adjusted.abs()).fold(0.0, f64::max);
            if !a.moved.is_empty() {
                out.push(format!("                        their largest |g_N| after it: {after:.3e}"));
            }
        }
    }
}

/// How the pair imposes contact: the integration, with mortar its multipliers and
/// transfer (balanced: where M recombines the basis), and the friction law.
fn integration_text(p: &PairCheck) -> String {
    let s = &p.settings;
    let how = match s.integration {
        Integration::Node => "node-to-surface (the paper's)".to_string(),
        Integration::Mortar => {
            let transfer = match (s.transfer, p.balance) {
                (MortarTransfer::Trace, _) => "trace (the master's faces)".to_string(),
                (MortarTransfer::Surface, _) => "surface (the master surface's basis)".to_string(),
                (MortarTransfer::Balanced, Some((region, n, defect))) => format!("balanced (the surface's basis recombined on {region} of {n} master nodes; M q − f: {defect:.1e} of max f)"),
                (MortarTransfer::Balanced, None) => "balanced (a facet master: its basis is its faces')".to_string(),
            };
            let mult = match s.multipliers {
                MortarMultipliers::Standard => "standard",
                MortarMultipliers::Dual => "dual",
            };
            let quadrature = match s.quadrature {
                MortarQuadrature::Cells => "",
                MortarQuadrature::KnotSpans => ", segments cut by the knot spans (64 points per triangle)",
            };
            format!("mortar over {} slave faces, {mult} multipliers, transfer {transfer}{quadrature}", p.slave_faces)
        }
    };
    let friction = if s.frictional() { format!("Coulomb μ = {}, ε_T = {:.4e}", s.mu, s.eps_t) } else { "frictionless".to_string() };
    format!("{how}; {friction}")
}

/// The readable summary, one line per entry.
pub fn summary(r: &CheckReport) -> Vec<String> {
    let mut out = vec![
        format!("splinecontact check {VERSION}: {} with setup {}", r.source, r.setup),
        format!("model: {} nodes, {} hexahedra, {} dofs ({} free), {} contact pairs, {} bodies", r.nodes, r.hexes, r.dofs, r.free_dofs, r.pairs.len(), r.bodies.len()),
    ];
    for p in &r.pairs {
        pair_lines(p, &mut out);
    }
    out.push("bodies and rigid-body modes (each body's centroid; rotations about it):".into());
    for b in &r.bodies {
        let c = b.centroid;
        let what = if b.free.is_empty() {
            "held: the constraints restrain all six rigid modes".to_string()
        } else {
            format!(
                "FREE: {}{}",
                b.free_list(),
                if b.contact_pairs.is_empty() { " (no contact pair touches it)".to_string() } else { format!(" (contact: {})", b.contact_pairs.join(", ")) }
            )
        };
        out.push(format!("  {}: {} nodes, {} constrained dofs, centroid ({:.4e}, {:.4e}, {:.4e}): {what}", b.name, b.nodes.len(), b.constrained_dofs, c[0], c[1], c[2]));
        if b.free.iter().any(|m| m.single().is_none()) {
            out.push(format!("    (a combined mode is a unit vector over the six; rotations in units of 1/L, L = {:.4e})", b.length));
        }
    }
    let (errors, warnings) = (r.errors(), r.warnings());
    for e in &errors {
        out.push(format!("error: {e}"));
    }
    for w in &warnings {
        out.push(format!("warning: {w}"));
    }
    out.push(format!("result: {} errors, {} warnings ({:.2} s)", errors.len(), warnings.len(), r.seconds));
    out
}

fn num(v: f64) -> String {
    if v.is_nan() {
        "NaN".into()
    } else {
        format!("{v:e}")
    }
}

/// The per-node CSV (columns [`CSV_COLUMNS`]).
pub fn write_csv(r: &CheckReport, path: &Path) -> Result<(), StageError> {
    write_atomic_with(path, |w: &mut dyn Write| {
        writeln!(w, "{}", CSV_COLUMNS.join(","))?;
        for p in &r.pairs {
            for row in &p.rows {
                let reason = match row.projected {
                    Projected::Failed(why) => why.word(),
                    _ => "",
                };
                let behind = match row.behind {
                    Some(true) => "1",
                    Some(false) => "0",
                    None => "",
                };
                writeln!(
                    w,
                    "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
                    p.name,
                    row.tag,
                    num(row.x[0]),
                    num(row.x[1]),
                    num(row.x[2]),
                    row.projected.word(),
                    reason,
                    num(row.g_n),
                    num(row.xi[0]),
                    num(row.xi[1]),
                    num(row.n_bar[0]),
                    num(row.n_bar[1]),
                    num(row.n_bar[2]),
                    row.penetrating as u8,
                    behind,
                    num(row.adjust_move),
                    num(row.g_n_adjusted),
                    row.flag().word()
                )?;
            }
        }
        Ok(())
    })
}

/// The slave nodes of every pair as a `.vtu` point cloud (one vertex per pair and
/// slave node, at its reference position), with the CSV's fields as point data.
pub fn vtu_grid(r: &CheckReport) -> Grid {
    let mut g = Grid::default();
    let (mut pair, mut tag, mut projection, mut g_n, mut xi, mut normal) = (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let (mut penetrating, mut behind, mut adjust_move, mut g_n_adjusted, mut flag) = (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for (k, p) in r.pairs.iter().enumerate() {
        for row in &p.rows {
            let i = g.points.len() as u32;
            g.points.push([row.x[0], row.x[1], row.x[2]]);
            g.push_cell(CellKind::Vertex, &[i]);
            pair.push(k as i32);
            tag.push(row.tag as i64);
            projection.push(row.projected.code());
            g_n.push(row.g_n);
            xi.extend([row.xi[0], row.xi[1], 0.0]);
            normal.extend(row.n_bar.iter().copied());
            penetrating.push(row.penetrating as u8);
            behind.push(row.behind.map_or(-1, |b| b as i32));
            adjust_move.push(row.adjust_move);
            g_n_adjusted.push(row.g_n_adjusted);
            flag.push(row.flag() as i32);
        }
    }
    let int = |name: &str, v: Vec<i32>| Field { name: name.into(), components: 1, values: FieldValues::I32(v) };
    g.point_data = vec![
        int("pair", pair),
        Field { name: "gmsh_node_tag".into(), components: 1, values: FieldValues::I64(tag) },
        int("projection", projection),
        Field::scalar_f64("g_n", g_n),
        Field::vector_f64("xi", xi),
        Field::vector_f64("normal", normal),
        Field { name: "penetrating".into(), components: 1, values: FieldValues::U8(penetrating) },
        int("behind", behind),
        Field::scalar_f64("adjust_move", adjust_move),
        Field::scalar_f64("g_n_adjusted", g_n_adjusted),
        int("flag", flag),
    ];
    g
}

/// Write the `.vtu` ([`vtu_grid`]).
pub fn write_vtu(r: &CheckReport, path: &Path) -> Result<(), VtkError> {
    vtu_grid(r).write_vtu(path)
}

/// Write the summary to a file.
pub fn write_summary(r: &CheckReport, path: &Path) -> Result<(), StageError> {
    let mut text = summary(r).join("\n");
    text.push('\n');
    write_atomic(path, text.as_bytes())
}

/// What `sc-solve` logs of the check at its start (lines): each pair's adjust (how
/// many nodes moved, how far, the first of them) and the penetrations it starts with.
pub fn solve_start_lines(r: &CheckReport) -> Vec<String> {
    let mut out = Vec::new();
    for p in &r.pairs {
        if let Some(a) = &p.adjustment {
            let tag = |node: u32| p.rows.iter().find(|r| r.node == node).map_or(node as u64, |r| r.tag);
            let listed: Vec<String> = a.moved.iter().take(10).map(|m| format!("{} by {:.3e}", tag(m.node), m.g_n.abs())).collect();
            out.push(format!(
                "contact pair '{}': adjust {:e} moved {} slave nodes onto the master, stress-free{}{}",
                p.name,
                a.distance,
                a.moved.len(),
                a.largest().map_or(String::new(), |m| format!(" (largest {:.4e}, node {})", m.g_n.abs(), tag(m.node))),
                if listed.is_empty() { String::new() } else { format!(": nodes {}{}", listed.join(", "), if a.moved.len() > 10 { ", … (sc-check's CSV lists them all)" } else { "" }) }
            ));
        }
        let pen = p.penetrating_after_adjust();
        if !pen.is_empty() {
            let worst = pen.iter().map(|r| -r.g_n).fold(0.0, f64::max);
            out.push(format!("contact pair '{}': {} slave nodes start penetrating the master beyond the tolerance (deepest {worst:.4e}; sc-check lists them)", p.name, pen.len()));
        }
    }
    out
}

/// What `sc-solve` warns about at its start: free rigid-body modes by body, and
/// flipped masters solved by `allow_flipped_master`.
pub fn solve_start_warnings(r: &CheckReport) -> Vec<String> {
    let mut out = Vec::new();
    for p in &r.pairs {
        if p.orientation.flipped() && p.allow_flipped_master {
            out.push(format!(
                "contact pair '{}': the master normal points away from the slave body ({} of {} nodes see it from behind); solving anyway, as allow_flipped_master asks",
                p.name, p.orientation.behind, p.orientation.voters
            ));
        }
    }
    out.extend(r.bodies.iter().filter_map(crate::check::rigid_modes::BodyModes::warning));
    out
}
