//! Build script of splinecontact (`Cargo.toml`: `build = "lib/solver/petsc/build.rs"`).
//!
//! The default build needs nothing from it. With `--features petsc` it finds PETSc
//! (≥ 3.18, real double, 32-bit `PetscInt`) and MPI through `pkg-config` (or
//! `PETSC_DIR`/`PETSC_ARCH`), compiles `shim.c` (the constants of the installed
//! headers and the few calls that need an `MPI_Comm`) and links `libpetsc` and
//! `libmpi`. A machine without them gets a message that says what to install.

fn main() {
    println!("cargo:rerun-if-changed=lib/solver/petsc/shim.c");
    println!("cargo:rerun-if-changed=lib/solver/petsc/build.rs");
    println!("cargo:rerun-if-env-changed=PETSC_DIR");
    println!("cargo:rerun-if-env-changed=PETSC_ARCH");
    println!("cargo:rerun-if-env-changed=PKG_CONFIG_PATH");
    #[cfg(feature = "petsc")]
    petsc::build();
}

#[cfg(feature = "petsc")]
mod petsc {
    use std::path::PathBuf;
    use std::process::Command;

    const INSTALL: &str = "the `petsc` feature needs PETSc (>= 3.18, real, double, 32-bit indices) and MPI with their headers.\n\
         On Debian/Ubuntu:  sudo apt-get install libpetsc-real-dev libopenmpi-dev openmpi-bin pkg-config\n\
         Elsewhere: set PETSC_DIR (and PETSC_ARCH) to a PETSc build, or put PETSc.pc on PKG_CONFIG_PATH.\n\
         The default build (without --features petsc) needs none of this.";

    /// `-I`, `-L` and `-l` flags of a pkg-config package, or `None` when it is missing.
    fn pkg_config(package: &str) -> Option<Vec<String>> {
        let out = Command::new("pkg-config").args(["--cflags", "--libs", package]).output().ok()?;
        if !out.status.success() {
            return None;
        }
        Some(String::from_utf8_lossy(&out.stdout).split_whitespace().map(str::to_owned).collect())
    }

    struct Found {
        include: Vec<PathBuf>,
        lib_dirs: Vec<PathBuf>,
        libs: Vec<String>,
    }

    impl Found {
        fn add(&mut self, flags: &[String]) {
            for f in flags {
                if let Some(p) = f.strip_prefix("-I") {
                    self.include.push(p.into());
                } else if let Some(p) = f.strip_prefix("-L") {
                    self.lib_dirs.push(p.into());
                } else if let Some(l) = f.strip_prefix("-l") {
                    self.libs.push(l.to_owned());
                }
            }
        }
    }

    fn fail(what: &str) -> ! {
        panic!("\n\nsplinecontact: {what}\n{INSTALL}\n\n");
    }

    pub fn build() {
        let mut found = Found { include: Vec::new(), lib_dirs: Vec::new(), libs: Vec::new() };
        if let Ok(dir) = std::env::var("PETSC_DIR") {
            let dir = PathBuf::from(dir);
            let arch = std::env::var("PETSC_ARCH").unwrap_or_default();
            found.include.push(dir.join("include"));
            found.include.push(dir.join(&arch).join("include"));
            found.lib_dirs.push(dir.join(&arch).join("lib"));
            found.libs.push("petsc".into());
        } else if let Some(flags) = pkg_config("PETSc").or_else(|| pkg_config("petsc")) {
            found.add(&flags);
        } else {
            fail("PETSc was not found (neither PETSC_DIR nor pkg-config's PETSc.pc).");
        }
        match pkg_config("mpi").or_else(|| pkg_config("ompi")).or_else(|| pkg_config("mpich")) {
            Some(flags) => found.add(&flags),
            None => fail("MPI was not found (pkg-config knows neither mpi, ompi nor mpich)."),
        }
        let header = found.include.iter().any(|d| d.join("petscksp.h").exists());
        if !header {
            fail(&format!("petscksp.h is in none of {:?}.", found.include));
        }
        let mut cc = cc::Build::new();
        cc.file("lib/solver/petsc/shim.c").warnings(false);
        for d in &found.include {
            cc.include(d);
        }
        if let Err(e) = cc.try_compile("splinecontact_petsc_shim") {
            fail(&format!("compiling lib/solver/petsc/shim.c against the installed PETSc failed: {e}"));
        }
        for d in &found.lib_dirs {
            println!("cargo:rustc-link-search=native={}", d.display());
            println!("cargo:rustc-link-arg=-Wl,-rpath,{}", d.display());
        }
        for l in &found.libs {
            println!("cargo:rustc-link-lib={l}");
        }
    }
}
