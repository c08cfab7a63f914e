//! Will the factorization fit? Checked after the symbolic analysis, before any
//! numeric work, so that a model too large for the machine stops with an estimate
//! instead of being killed by the operating system halfway through a
//! factorization.
//!
//! The estimate is that of the Cholesky (LLT/LDLT) factor, which the symbolic
//! analysis sizes exactly: its `nnz(L)` values at 8 bytes, times 1.25 for the
//! numeric phase's workspace and update matrices, plus the assembled matrix (values
//! and indices) and the per-unknown vectors. The 1.25 is a margin over a
//! measurement on the 2-core reference machine: an LDLT with 558 M values in L
//! (4.5 GB, 201,720 unknowns) peaked at 5.1 GB resident, 1.15 times the factor.
//! An LU factor (friction's fallback) cannot be sized before its numeric phase
//! (partial pivoting decides its fill). On the reference machine it took 4 to 5
//! times the memory of the Cholesky factor of the same matrix's symmetric part (8.2
//! GB at 108,537 unknowns), so it is checked before its numeric phase at
//! [`LU_OVER_CHOLESKY`] times that factor's estimate ([`check_lu`]).
//!
//! What is available: `SC_MEMORY_LIMIT` (bytes, with an optional `K`, `M` or `G`
//! suffix, powers of 1024) when set, else `MemAvailable` of `/proc/meminfo`; where
//! neither is known nothing is checked.

/// Bytes available for the factorization, if known.
pub fn available() -> Option<u64> {
    if let Ok(s) = std::env::var("SC_MEMORY_LIMIT") {
        return parse_size(&s);
    }
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = meminfo.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// `123`, `64K`, `512M`, `2G` (powers of 1024).
pub fn parse_size(s: &str) -> Option<u64> {
    let s = s.trim();
    let (digits, mult) = match s.chars().last()? {
        'K' | 'k' => (&s[..s.len() - 1], 1u64 << 10),
        'M' | 'm' => (&s[..s.len() - 1], 1 << 20),
        'G' | 'g' => (&s[..s.len() - 1], 1 << 30),
        _ => (s, 1),
    };
    digits.trim().parse::<u64>().ok()?.checked_mul(mult)
}

/// The estimated peak of a Cholesky factorization with `factor_values` values in L,
/// of an `n`-unknown matrix with `matrix_values` stored values.
pub fn cholesky_bytes(factor_values: usize, n: usize, matrix_values: usize) -> u64 {
    let f = factor_values as u64;
    // L with a quarter more (workspace), the matrix (values + row indices), per-unknown vectors
    10 * f + 16 * matrix_values as u64 + 64 * n as u64
}

/// `1.5 GiB`, `12.0 MiB`, `800 KiB`.
fn human(b: u64) -> String {
    match b {
        b if b >= 1 << 30 => format!("{:.1} GiB", b as f64 / (1u64 << 30) as f64),
        b if b >= 1 << 20 => format!("{:.1} MiB", b as f64 / (1u64 << 20) as f64),
        b => format!("{} KiB", b.div_ceil(1024)),
    }
}

/// The LU factor's memory over the Cholesky factor's of the symmetric part (the
/// upper end of the 4–5 measured on 3D hexahedral meshes).
pub const LU_OVER_CHOLESKY: u64 = 5;

/// The factorization does not fit: what it needs and what there is.
#[derive(Debug, Clone, PartialEq)]
pub struct TooLarge {
    /// "sparse Cholesky factorization", "LU factorization".
    pub what: &'static str,
    pub unknowns: usize,
    pub factor_values: usize,
    pub needed: u64,
    pub available: u64,
}

impl std::fmt::Display for TooLarge {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the model is too large for this machine's memory: the {} of its {} unknowns holds {} values and needs about {}, {} are available{}; use a coarser mesh, or the iterative solver of a `--features petsc` build (linear_solver: petsc), whose memory grows linearly",
            self.what,
            self.unknowns,
            self.factor_values,
            human(self.needed),
            human(self.available),
            if std::env::var_os("SC_MEMORY_LIMIT").is_some() { " (SC_MEMORY_LIMIT)" } else { "" }
        )
    }
}

/// Check a Cholesky factorization against the available memory.
pub fn check_cholesky(factor_values: usize, n: usize, matrix_values: usize) -> Result<(), TooLarge> {
    let needed = cholesky_bytes(factor_values, n, matrix_values);
    match available() {
        Some(available) if needed > available => Err(TooLarge { what: "sparse Cholesky factorization", unknowns: n, factor_values, needed, available }),
        _ => Ok(()),
    }
}

/// Check an LU factorization (the frictional tangent's fallback, after GMRES
/// preconditioned by the symmetric part fails) against `available` bytes, from the
/// symmetric part's Cholesky factor of `cholesky_values` values: the LU is taken at
/// [`LU_OVER_CHOLESKY`] times that factor (module docs).
pub fn check_lu(cholesky_values: usize, n: usize, matrix_values: usize, available: Option<u64>) -> Result<(), TooLarge> {
    let factor_values = cholesky_values.saturating_mul(LU_OVER_CHOLESKY as usize);
    let needed = LU_OVER_CHOLESKY.saturating_mul(10 * cholesky_values as u64) + 16 * matrix_values as u64 + 64 * n as u64;
    match available {
        Some(available) if needed > available => Err(TooLarge { what: "LU factorization (the fallback of the frictional tangent's GMRES solve)", unknowns: n, factor_values, needed, available }),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The LU check: 108,537 unknowns whose symmetric part's Cholesky factor holds
    /// 180 M values (about 1.7 GiB, as on the crossed beams at n = 10) need about
    /// 8.4 GiB as LU, against the 8.2 GB measured: refused with 4 GiB, let through
    /// with 16 GiB or when the memory is unknown; the message names the LU.
    #[test]
    fn lu_fallback_is_sized() {
        let (chol, n, nnz) = (180_000_000, 108_537, 12_000_000);
        let e = check_lu(chol, n, nnz, Some(4 << 30)).unwrap_err();
        assert!(e.needed > 8 << 30 && e.needed < 9 << 30, "{}", human(e.needed));
        let msg = e.to_string();
        assert!(msg.contains("LU factorization") && msg.contains("108537 unknowns") && msg.contains("4.0 GiB are available"), "{msg}");
        assert!(check_lu(chol, n, nnz, Some(16 << 30)).is_ok());
        assert!(check_lu(chol, n, nnz, None).is_ok());
    }

    #[test]
    fn sizes() {
        assert_eq!(parse_size("64K"), Some(65536));
        assert_eq!(parse_size("2G"), Some(2 << 30));
        assert_eq!(parse_size(" 100 "), Some(100));
        assert_eq!(parse_size("lots"), None);
        assert_eq!(parse_size("99999999999999G"), None);
    }
}
