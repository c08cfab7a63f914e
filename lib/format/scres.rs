//! The results stage file, `.scres` (format `scres`, version 2.1): the mesh, the
//! setup that produced it, and the full state of every converged increment
//! (displacements, Cauchy stress at the Gauss points, reactions, convergence
//! history), so that a run can be inspected, exported or restarted from it.
//!
//! The file grows by one segment per converged increment ([`ResultsFile`]): the
//! first write creates it atomically (temporary file, renamed), every later
//! increment is appended and synced, and the run's status closes it. What is on
//! disk is always every increment converged so far; an append cut short by a crash
//! is left out by readers (and said, [`Results::tail`]). Writing is linear in the
//! run's length: 1.x rewrote the whole file after every increment.

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::sccontact::{self, ContactPair, PairMeta};
use super::scmesh;
use super::stage::{write_atomic, SegmentEnd, StageError, StageFile, StageWriter};
use crate::mesh::Mesh;

pub const FORMAT: &str = "scres";
/// 2.0: one segment per increment, appended (1.x: one META listing every
/// increment, the whole file rewritten after each).
pub const MAJOR: u32 = 2;
pub const MINOR: u32 = 1;

/// One Newton iteration, as logged.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct IterationLog {
    pub iteration: u32,
    /// ‖R_free‖ / reference force.
    pub residual: f64,
    /// |Δu · R| / (Δu₀ · R₀).
    pub energy: f64,
    pub seconds_assembly: f64,
    pub seconds_factor: f64,
    pub seconds_solve: f64,
    /// Contact search (projections, groups, pattern rebuild).
    #[serde(default)]
    pub seconds_contact: f64,
    /// Slave nodes pressed into their master at this iterate (all pairs).
    #[serde(default)]
    pub contact_active: u32,
    /// Uzawa update this Newton solve follows (0 = first solve of the increment).
    #[serde(default)]
    pub augmentation: u32,
    /// Krylov iterations of this iteration's linear solve (0 for a direct solve, and
    /// for the converged row, which solves nothing).
    #[serde(default)]
    pub krylov_iterations: u32,
}

/// Reaction force summed over a constrained node set.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Reaction {
    pub set: String,
    pub force: [f64; 3],
}

/// One contact pair at the end of an increment.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PairSummary {
    pub pair: String,
    /// Force the master exerts on the slave body, Σ −t_N A_s n̄.
    pub force: [f64; 3],
    /// Active slave nodes.
    pub active: u32,
    /// Largest penetration −g_N of an active node.
    pub max_penetration: f64,
    /// Uzawa updates this increment needed.
    pub augmentations: u32,
    /// False when the augmentations ran out with the penetration still above tolerance.
    pub penetration_converged: bool,
    /// Slave nodes whose closest-point projection failed (counted as out of contact).
    #[serde(default, skip_serializing_if = "is_zero_u32")]
    pub unprojected: u32,
    /// Frictional pairs: the tangential part of `force`, and the active nodes sticking
    /// and slipping.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<FrictionSummary>,
    /// Pairs with a master-surface stabilisation (1.2): ‖f‖ of its force on the
    /// master net's nodes, to compare with `force`.
    #[serde(default, skip_serializing_if = "is_zero_f64")]
    pub stabilization_force: f64,
}

fn is_zero_f64(v: &f64) -> bool {
    *v == 0.0
}

fn is_zero_u32(v: &u32) -> bool {
    *v == 0
}

/// Friction of one pair at the end of an increment.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct FrictionSummary {
    pub tangential_force: [f64; 3],
    pub stick: u32,
    pub slip: u32,
    /// Largest elastic slip ‖t_T − t_{T,n}‖/ε_T of a sticking node (the penalty's
    /// tangential constraint violation; the augmented Lagrangian drives it below the
    /// tolerance).
    #[serde(default)]
    pub elastic_slip: f64,
}

/// Columns of the per-slave-node friction array `inc/<k>/pair/<p>/friction`
/// (frictional pairs only): the tangential traction vector t_T, the slip increment
/// (ξ̄ − ξ̄_n)^α ā_α of the increment, the covariant t_Tα (the history a restart needs,
/// with ξ̄ in `state`), and 0 (not active) / 1 (stick) / 2 (slip).
pub const FRICTION_COLUMNS: [&str; 9] = ["t_t_x", "t_t_y", "t_t_z", "slip_x", "slip_y", "slip_z", "t_t_1", "t_t_2", "stick_slip"];

/// Columns of the per-slave-node contact state array `inc/<k>/pair/<p>/state`.
pub const CONTACT_STATE_COLUMNS: [&str; 6] = ["g_n", "t_n", "lambda_n", "status", "xi_1", "xi_2"];

/// What is known of one converged increment besides its arrays.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct IncrementInfo {
    pub load_factor: f64,
    /// Attempts that were cut back before this increment converged.
    pub cutbacks: u32,
    pub iterations: Vec<IterationLog>,
    pub reactions: Vec<Reaction>,
    pub seconds_output: f64,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub contact: Vec<PairSummary>,
}

/// How the run ended (so far).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum RunStatus {
    Running,
    Completed,
    Stopped { reason: String },
}

/// One converged increment.
#[derive(Debug, Clone, PartialEq)]
pub struct Increment {
    pub info: IncrementInfo,
    /// Displacement of every node.
    pub u: Vec<[f64; 3]>,
    /// Cauchy stress at the 8 Gauss points of every hexahedron, row-major 3×3.
    pub stress: Vec<[[f64; 9]; 8]>,
    /// Per pair, per slave node: g_N, t_N, λ_N, status (−1 outside the patch, 0 open,
    /// 1 active), ξ̄¹, ξ̄² (see [`CONTACT_STATE_COLUMNS`]).
    pub contact: Vec<Vec<[f64; 6]>>,
    /// Per pair, per slave node: [`FRICTION_COLUMNS`]; empty for frictionless pairs.
    pub friction: Vec<Vec<[f64; 9]>>,
    /// Per pair, per face of its slave face set (the set's order): the mean contact
    /// pressure over the face (`post::contact_pressure`); empty for a node-set slave.
    pub face_pressure: Vec<Vec<f64>>,
    /// Per pair whose master is an atlas (docs/theory/masters.md), per slave node: the
    /// chart its ξ̄ in `contact` lies on (`u32::MAX`: none); empty for other pairs.
    pub charts: Vec<Vec<u32>>,
}

impl Increment {
    /// The displacements as one dof vector (x, y, z of node 0, then node 1, …).
    pub fn displacements(&self) -> Vec<f64> {
        self.u.iter().flatten().copied().collect()
    }
}

/// Where a restarted run came from: its first `increments` increments are those
/// of `file`, the last at `load_factor`.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RestartOrigin {
    pub file: String,
    pub increments: u32,
    pub load_factor: f64,
}

/// The first META record: the run.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ResultsMeta {
    source: String,
    /// The solve setup, as given (YAML text).
    setup: String,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pairs: Vec<PairMeta>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    restart: Option<RestartOrigin>,
}

/// The META record that opens each later segment: an increment's summary (its
/// arrays follow), or the status that closes the run.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct SegmentMeta {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    increment: Option<IncrementInfo>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    status: Option<StatusMeta>,
}

/// `completed`, or `stopped: {reason: ...}` (not a YAML `!tag`).
#[derive(Debug, Serialize, Deserialize)]
struct StatusMeta(#[serde(with = "serde_yaml::with::singleton_map")] RunStatus);

/// A results file in memory.
#[derive(Debug, Clone, PartialEq)]
pub struct Results {
    pub mesh: Mesh,
    pub source: String,
    pub setup: String,
    pub status: RunStatus,
    pub increments: Vec<Increment>,
    /// The contact pairs of the model (empty without contact).
    pub pairs: Vec<ContactPair>,
    /// A restarted run: the file it continued.
    pub restart: Option<RestartOrigin>,
    /// Read from a file whose last bytes were not a complete segment (an append cut
    /// short): why they were left out. Never written.
    pub tail: Option<String>,
}

impl Results {
    /// The whole file: the run's segment, one per increment, and the status unless
    /// the run is still going.
    pub fn encode(&self) -> Vec<u8> {
        self.encode_segments().0
    }

    fn encode_segments(&self) -> (Vec<u8>, SegmentEnd) {
        let mut w = StageWriter::new(FORMAT, MAJOR, MINOR);
        w.reserve(self.encoded_size_estimate(0));
        let meta = ResultsMeta {
            source: self.source.clone(),
            setup: self.setup.clone(),
            pairs: self.pairs.iter().map(sccontact::pair_meta).collect(),
            restart: self.restart.clone(),
        };
        w.meta(&serde_yaml::to_string(&meta).expect("results metadata serialises"));
        w.meta(&scmesh::mesh_meta_yaml(&self.mesh, &self.source));
        scmesh::write_mesh_records(&mut w, &self.mesh, "mesh/");
        for (k, p) in self.pairs.iter().enumerate() {
            // the pairs were checked when the contact model was read
            sccontact::write_pair_records(&mut w, k, p).expect("contact pair orders fit their nets");
        }
        w.end_segment();
        self.encode_tail(&mut w, 0);
        w.finish_segments()
    }

    /// About the bytes of the mesh and of increments `first..` (their arrays, with
    /// 64 KiB for the YAML records): what the writer reserves at once.
    fn encoded_size_estimate(&self, first: usize) -> usize {
        let (n, m) = (self.mesh.nodes.len(), self.mesh.hexes.len());
        let mesh = if first == 0 { n * 24 + m * 40 } else { 0 };
        let per_increment = |inc: &Increment| {
            n * 24 + m * 8 * 9 * 8 + inc.contact.iter().map(|s| s.len() * 48).sum::<usize>() + inc.friction.iter().map(|f| f.len() * 72).sum::<usize>() + inc.face_pressure.iter().map(|f| f.len() * 8).sum::<usize>()
        };
        (1 << 16) + mesh + self.increments.iter().skip(first).map(per_increment).sum::<usize>()
    }

    /// The segments of increments `first..` and, once the run ended, of its status.
    fn encode_tail(&self, w: &mut StageWriter, first: usize) {
        let (n, m) = (self.mesh.nodes.len() as u64, self.mesh.hexes.len() as u64);
        for (k, inc) in self.increments.iter().enumerate().skip(first) {
            let meta = SegmentMeta { increment: Some(inc.info.clone()), status: None };
            w.meta(&serde_yaml::to_string(&meta).expect("increment metadata serialises"));
            let u = inc.displacements();
            w.f64s(&format!("inc/{k}/u"), &[n, 3], &u);
            w.f64s(&format!("inc/{k}/stress"), &[m, 8, 9], inc.stress.as_flattened().as_flattened());
            for (p, state) in inc.contact.iter().enumerate() {
                let v: Vec<f64> = state.iter().flatten().copied().collect();
                w.f64s(&format!("inc/{k}/pair/{p}/state"), &[state.len() as u64, 6], &v);
            }
            for (p, fr) in inc.friction.iter().enumerate().filter(|(_, f)| !f.is_empty()) {
                let v: Vec<f64> = fr.iter().flatten().copied().collect();
                w.f64s(&format!("inc/{k}/pair/{p}/friction"), &[fr.len() as u64, 9], &v);
            }
            for (p, c) in inc.charts.iter().enumerate().filter(|(_, c)| !c.is_empty()) {
                w.u32s(&format!("inc/{k}/pair/{p}/chart"), &[c.len() as u64], c);
            }
            for (p, fp) in inc.face_pressure.iter().enumerate().filter(|(_, f)| !f.is_empty()) {
                w.f64s(&format!("inc/{k}/pair/{p}/face_pressure"), &[fp.len() as u64], fp);
            }
            w.end_segment();
        }
        if self.status != RunStatus::Running {
            let meta = SegmentMeta { increment: None, status: Some(StatusMeta(self.status.clone())) };
            w.meta(&serde_yaml::to_string(&meta).expect("status metadata serialises"));
            w.end_segment();
        }
    }

    /// Write atomically.
    pub fn write(&self, path: &Path) -> Result<(), StageError> {
        write_atomic(path, &self.encode())
    }

    pub fn from_stage(f: &StageFile) -> Result<Self, StageError> {
        let meta: ResultsMeta = f.meta_as()?;
        let mesh_meta = f.meta.get(1).ok_or_else(|| f.invalid("META", "the mesh metadata record is missing"))?;
        let mesh = scmesh::read_mesh_records(f, "mesh/", mesh_meta)?;
        let pairs: Vec<ContactPair> = meta.pairs.into_iter().enumerate().map(|(k, pm)| sccontact::read_pair(f, k, pm, mesh.nodes.len())).collect::<Result<_, _>>()?;
        // the later segments: increments in order, then the status (none yet: running)
        let (mut infos, mut status) = (Vec::new(), RunStatus::Running);
        for (r, text) in f.meta.iter().enumerate().skip(2) {
            let name = format!("META {}", r + 1);
            let seg: SegmentMeta = serde_yaml::from_str(text).map_err(|e| f.invalid(&name, e.to_string()))?;
            match (seg.increment, seg.status) {
                (Some(info), None) if status == RunStatus::Running => infos.push(info),
                (None, Some(StatusMeta(s))) if status == RunStatus::Running => status = s,
                _ => return Err(f.invalid(&name, "expected one increment (before the status) or the status")),
            }
        }
        let mut increments = Vec::with_capacity(infos.len());
        for (k, info) in infos.into_iter().enumerate() {
            let u = f.f64s(&format!("inc/{k}/u"), Some(3))?;
            if u.len() != 3 * mesh.nodes.len() {
                return Err(f.invalid(&format!("inc/{k}/u"), format!("expected {} nodes", mesh.nodes.len())));
            }
            let name = format!("inc/{k}/stress");
            let s = f.f64s(&name, None)?;
            if s.len() != 72 * mesh.hexes.len() {
                return Err(f.invalid(&name, format!("expected {} hexahedra × 8 Gauss points × 9", mesh.hexes.len())));
            }
            let stress = s
                .chunks_exact(72)
                .map(|c| std::array::from_fn(|q| std::array::from_fn(|i| c[9 * q + i])))
                .collect();
            let mut contact = Vec::with_capacity(pairs.len());
            for (p, pair) in pairs.iter().enumerate() {
                let name = format!("inc/{k}/pair/{p}/state");
                let v = f.f64s(&name, Some(6))?;
                if v.len() != 6 * pair.slave_nodes.len() {
                    return Err(f.invalid(&name, format!("expected {} slave nodes of pair '{}' × 6", pair.slave_nodes.len(), pair.name)));
                }
                contact.push(v.chunks_exact(6).map(|c| std::array::from_fn(|i| c[i])).collect());
            }
            let mut friction = Vec::with_capacity(pairs.len());
            for (p, pair) in pairs.iter().enumerate() {
                let name = format!("inc/{k}/pair/{p}/friction");
                if f.array(&name).is_none() {
                    friction.push(Vec::new());
                    continue;
                }
                let v = f.f64s(&name, Some(9))?;
                if v.len() != 9 * pair.slave_nodes.len() {
                    return Err(f.invalid(&name, format!("expected {} slave nodes of pair '{}' × 9", pair.slave_nodes.len(), pair.name)));
                }
                friction.push(v.chunks_exact(9).map(|c| std::array::from_fn(|i| c[i])).collect());
            }
            let mut face_pressure = Vec::with_capacity(pairs.len());
            for (p, pair) in pairs.iter().enumerate() {
                let name = format!("inc/{k}/pair/{p}/face_pressure");
                if f.array(&name).is_none() {
                    face_pressure.push(Vec::new());
                    continue;
                }
                let v = f.f64s(&name, None)?;
                let faces = mesh.face_set(&pair.slave).map_or(0, |fs| fs.faces.len());
                if v.len() != faces {
                    return Err(f.invalid(&name, format!("expected one value per face of slave face set '{}' ({faces})", pair.slave)));
                }
                face_pressure.push(v.to_vec());
            }
            let mut charts = Vec::with_capacity(pairs.len());
            for (p, pair) in pairs.iter().enumerate() {
                let name = format!("inc/{k}/pair/{p}/chart");
                if f.array(&name).is_none() {
                    charts.push(Vec::new());
                    continue;
                }
                let v = f.u32s(&name, None)?;
                if v.len() != pair.slave_nodes.len() {
                    return Err(f.invalid(&name, format!("expected one chart per slave node of pair '{}' ({})", pair.name, pair.slave_nodes.len())));
                }
                charts.push(v.to_vec());
            }
            increments.push(Increment { info, u: u.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(), stress, contact, friction, face_pressure, charts });
        }
        Ok(Self { mesh, source: meta.source, setup: meta.setup, status, increments, pairs, restart: meta.restart, tail: f.tail.clone() })
    }

    pub fn read(path: &Path) -> Result<Self, StageError> {
        Self::from_stage(&StageFile::read(path, Some((FORMAT, MAJOR)))?)
    }
}

/// The results file of a running solve, written as the run goes: the first
/// [`ResultsFile::sync`] creates it atomically with everything so far (a temporary
/// file renamed onto it, so an existing file survives until then); each later one
/// appends the increments converged since, and the status once the run ended, as
/// segments, then syncs. A crash in an append leaves a partial last segment, which
/// readers leave out.
pub struct ResultsFile {
    path: PathBuf,
    /// The open file and where its last segment ended, once created.
    open: Option<(fs::File, SegmentEnd)>,
    /// Increments on disk; whether the status is.
    written: usize,
    closed: bool,
    /// Bytes written and seconds spent writing (encoding, writing, syncing).
    pub bytes: u64,
    pub seconds: f64,
    /// Appends made so far (for the fault injection of [`kill_in_append`]).
    appends: usize,
}

/// Fault injection for the crash tests: with `SC_FAULT_KILL_IN_APPEND=K:F` the K-th
/// append (1-based) writes the first fraction F of its bytes, syncs them and sends
/// SIGKILL to its own process: a kill inside `write`, landed where the test wants
/// it instead of where chance puts it (`tests/verification/crash.rs`).
fn kill_in_append(append: usize) -> Option<f64> {
    let v = std::env::var("SC_FAULT_KILL_IN_APPEND").ok()?;
    let (k, f) = v.split_once(':')?;
    (k.trim().parse::<usize>().ok()? == append).then_some(())?;
    f.trim().parse::<f64>().ok().filter(|f| (0.0..=1.0).contains(f))
}

/// SIGKILL this process (through `kill`, the standard tool: no signal crate for
/// one test hook) and wait for it; without that tool, abort (SIGABRT leaves the
/// file as SIGKILL does: nothing runs after it).
fn kill_self() -> ! {
    let sent = std::process::Command::new("kill").args(["-KILL", &std::process::id().to_string()]).status().is_ok_and(|s| s.success());
    if sent {
        std::thread::sleep(std::time::Duration::from_secs(10));
    }
    std::process::abort()
}

impl ResultsFile {
    pub fn new(path: &Path) -> Self {
        Self { path: path.to_path_buf(), open: None, written: 0, closed: false, bytes: 0, seconds: 0.0, appends: 0 }
    }

    /// A results file that is never written (an MPI rank other than the first, which
    /// computes the same increments and leaves the writing to rank 0).
    pub fn not_written(path: &Path) -> Self {
        Self { closed: true, ..Self::new(path) }
    }

    /// Bring the file up to date with `results` (which only ever grows: more
    /// increments, then a status).
    pub fn sync(&mut self, results: &Results) -> Result<(), StageError> {
        if self.closed {
            return Ok(());
        }
        let start = Instant::now();
        let shown = || self.path.display().to_string();
        match &mut self.open {
            None => {
                let (bytes, end) = results.encode_segments();
                write_atomic(&self.path, &bytes)?;
                let file = fs::OpenOptions::new().append(true).open(&self.path).map_err(|source| StageError::Io { path: shown(), action: "open for appending", source })?;
                self.bytes += bytes.len() as u64;
                self.open = Some((file, end));
            }
            Some((file, end)) => {
                let mut w = StageWriter::append_to(*end);
                w.reserve(results.encoded_size_estimate(self.written));
                results.encode_tail(&mut w, self.written);
                let (bytes, new_end) = w.finish_segments();
                self.appends += 1;
                if let Some(f) = kill_in_append(self.appends) {
                    let _ = file.write_all(&bytes[..(bytes.len() as f64 * f) as usize]).and_then(|_| file.sync_data());
                    kill_self();
                }
                file.write_all(&bytes).and_then(|_| file.sync_data()).map_err(|source| StageError::Io { path: self.path.display().to_string(), action: "append to", source })?;
                self.bytes += bytes.len() as u64;
                *end = new_end;
            }
        }
        self.written = results.increments.len();
        self.closed = results.status != RunStatus::Running;
        self.seconds += start.elapsed().as_secs_f64();
        Ok(())
    }
}
