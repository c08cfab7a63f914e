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
//! An LU factor (friction's fallback) is not sized before its numeric phase
//! (partial pivoting decides its fill) and is not checked; on the reference machine
//! it took 4 to 5 times the memory of the Cholesky factor of the same matrix.
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

/// The factorization does not fit: what it needs and what there is.
#[derive(Debug, Clone, PartialEq)]
pub struct TooLarge {
    pub unknowns: usize,
    pub factor_values: usize,
    pub needed: u64,
    pub available: u64,
}

impl std::fmt::Display for TooLarge {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the model is too large for this machine's memory: the sparse Cholesky factorization of its {} unknowns holds {} values and needs about {}, {} are available{}; use a coarser mesh, or the iterative solver of a `--features petsc` build (linear_solver: petsc), whose memory grows linearly",
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
        Some(available) if needed > available => Err(TooLarge { unknowns: n, factor_values, needed, available }),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes() {
        assert_eq!(parse_size("64K"), Some(65536));
        assert_eq!(parse_size("2G"), Some(2 << 30));
        assert_eq!(parse_size(" 100 "), Some(100));
        assert_eq!(parse_size("lots"), None);
        assert_eq!(parse_size("99999999999999G"), None);
    }
}
