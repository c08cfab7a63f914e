//! Which share of the work this process does when the program runs under
//! `mpirun`: its rank, the number of ranks, and the nodes it owns.
//!
//! A build without the `petsc` feature is always rank 0 of 1; when it finds
//! itself started by `mpirun` with several ranks ([`launcher_ranks`]), the
//! programs say that they run serially and let only the first rank work.

/// This process's rank and the number of ranks: PETSc's communicator once PETSc
/// has started, `(0, 1)` otherwise.
pub fn rank_and_size() -> (usize, usize) {
    #[cfg(feature = "petsc")]
    {
        super::petsc::runtime::rank_and_size()
    }
    #[cfg(not(feature = "petsc"))]
    {
        (0, 1)
    }
}

/// The rank and size an MPI launcher (Open MPI, MPICH/Hydra, PMIx, Slurm) gave this
/// process through its environment, when it was started by one.
pub fn launcher_ranks() -> Option<(usize, usize)> {
    let read = |name: &str| std::env::var(name).ok().and_then(|v| v.trim().parse::<usize>().ok());
    let pairs = [
        ("OMPI_COMM_WORLD_RANK", "OMPI_COMM_WORLD_SIZE"),
        ("PMIX_RANK", "PMIX_SIZE"),
        ("PMI_RANK", "PMI_SIZE"),
        ("SLURM_PROCID", "SLURM_NTASKS"),
    ];
    pairs.iter().find_map(|(r, s)| Some((read(r)?, read(s)?)))
}

/// The nodes `first..last` the current rank owns among `n_nodes`: contiguous
/// ranges of near-equal size, in node order.
pub fn owned_nodes(n_nodes: usize) -> (usize, usize) {
    let (rank, size) = rank_and_size();
    split(n_nodes, rank, size)
}

/// Rank `rank`'s range of `n` items split into `size` near-equal contiguous parts
/// (the first `n % size` parts one longer).
pub fn split(n: usize, rank: usize, size: usize) -> (usize, usize) {
    let (q, r) = (n / size, n % size);
    let first = rank * q + rank.min(r);
    (first, first + q + usize::from(rank < r))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_parts_cover_every_item_once() {
        for n in [0usize, 1, 7, 10] {
            for size in 1..5 {
                let mut next = 0;
                for rank in 0..size {
                    let (a, b) = split(n, rank, size);
                    assert_eq!(a, next);
                    assert!(b - a <= n / size + 1);
                    next = b;
                }
                assert_eq!(next, n);
            }
        }
    }
}

/// How a program takes part in an `mpirun` launch.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Participation {
    /// Not under `mpirun`, or under it with one rank.
    Alone,
    /// One of `size` ranks of a distributed solve (a build with the PETSc backend:
    /// PETSc and MPI are started).
    Rank { rank: usize, size: usize },
    /// Rank 0 of a launch this build cannot distribute: it works alone, after saying
    /// so (the text).
    Serial(String),
    /// Another rank of such a launch: it stops at once, successfully.
    Idle,
}

/// What a program does under `mpirun`, decided before it reads anything.
/// `distributed`: the program distributes its work (sc-solve) in a build that can.
pub fn participate(program: &str, distributed: bool) -> Result<Participation, String> {
    let Some((rank, size)) = launcher_ranks().filter(|&(_, size)| size > 1) else {
        return Ok(Participation::Alone);
    };
    #[cfg(not(feature = "petsc"))]
    let _ = distributed;
    #[cfg(feature = "petsc")]
    if distributed {
        super::petsc::runtime::initialize().map_err(|e| e.to_string())?;
        let (rank, size) = rank_and_size();
        return Ok(Participation::Rank { rank, size });
    }
    if cfg!(feature = "petsc") {
        // rank 0 alone could still start PETSc, whose MPI would wait for the others
        return Err(format!("{program} runs serially: start it without mpirun (sc-solve is the program that distributes a solve under mpirun)"));
    }
    let why = format!("this {program} was built without the PETSc backend (cargo build --release --features petsc)");
    Ok(if rank == 0 {
        Participation::Serial(format!("started by mpirun with {size} ranks, but {why}: it runs serially on rank 0; the other ranks stop"))
    } else {
        Participation::Idle
    })
}

/// The program's last word to MPI: stops PETSc and MPI when they were started.
pub fn finish() {
    #[cfg(feature = "petsc")]
    super::petsc::runtime::finalize();
}

/// How [`reduce_over_ranks`] combines the ranks' values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reduction {
    Sum,
    Max,
}

/// Combines `x` over all ranks, in place (nothing to do on one).
pub fn reduce_over_ranks(x: &mut [f64], op: Reduction) -> Result<(), String> {
    #[cfg(feature = "petsc")]
    {
        let reduced = match op {
            Reduction::Sum => super::petsc::runtime::sum_over_ranks(x),
            Reduction::Max => super::petsc::runtime::max_over_ranks(x),
        };
        reduced.map_err(|e| e.to_string())
    }
    #[cfg(not(feature = "petsc"))]
    {
        let _ = (x, op);
        Ok(())
    }
}
