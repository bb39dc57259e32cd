//! Finding and opening Intel Open Image Denoise at run time (docs/design/tracer.md §3.11): the library is
//! never linked, so `mcctrace` starts and renders on a machine without it, and only `--denoise`
//! asks for it. Where it is looked for, in order (the first rule that names a place decides):
//!
//! 1. `MCCTRACE_OIDN`: the library file itself, or a folder holding it directly or in `lib/`
//!    (the `pyoidn` wheel's `oidn` folder, or its `lib` folder). Set but not loadable: an error
//!    naming it, no fall-back, so a typo is not hidden by another copy.
//! 2. The project's Python environment: `.venv/lib/python*/site-packages/pyoidn/oidn/lib/` in
//!    the current directory, where [`INSTALL_COMMAND`] puts it.
//! 3. The system's dynamic loader (`LD_LIBRARY_PATH`, the system library folders).
//!
//! The wheel's libraries find their own dependencies (OIDN's core and CPU device, TBB) beside
//! themselves through their `$ORIGIN` run path, so opening the main library by absolute path is
//! enough.

use super::DenoiseError;
use std::ffi::{c_char, c_int, c_void};
use std::path::{Path, PathBuf};

/// The one command that installs the denoiser where [`find_library`] looks (rule 2), run in the
/// folder `mcctrace` runs from: Intel's official OIDN 2.5.1 build, as the Python registry's
/// `pyoidn` wheel carries it (no numpy needed: only its libraries are used).
pub const INSTALL_COMMAND: &str =
    "python3 -m venv .venv && .venv/bin/python -m pip install --no-deps pyoidn==2.5.1.0";

/// The environment variable naming the library or its folder (rule 1).
pub const ENV_VAR: &str = "MCCTRACE_OIDN";

/// The library's file name (OIDN 2.x's soname).
const LIB_NAME: &str = "libOpenImageDenoise.so.2";

/// Where the library is to be loaded from, by the rules above.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Location {
    /// A file path (rules 1 and 2).
    File(PathBuf),
    /// The bare name, for the system's loader (rule 3).
    System,
}

/// Applies the rules: `env` is `MCCTRACE_OIDN`'s value, `cwd` the current directory.
pub fn find_library(env: Option<&Path>, cwd: &Path) -> Result<Location, DenoiseError> {
    if let Some(given) = env {
        let candidates = [given.to_path_buf(), given.join(LIB_NAME), given.join("lib").join(LIB_NAME)];
        return candidates.into_iter().find(|p| p.is_file()).map(Location::File).ok_or_else(|| {
            DenoiseError::NotFound {
                looked: format!(
                    "{ENV_VAR}={} (neither {LIB_NAME} nor a folder holding it, directly or in lib/)",
                    given.display()
                ),
            }
        });
    }
    let venv_lib = cwd.join(".venv").join("lib");
    if let Ok(entries) = std::fs::read_dir(&venv_lib) {
        let mut found: Vec<PathBuf> = entries
            .filter_map(|e| e.ok())
            .map(|e| e.path().join("site-packages/pyoidn/oidn/lib").join(LIB_NAME))
            .filter(|p| p.is_file())
            .collect();
        found.sort();
        if let Some(path) = found.pop() {
            return Ok(Location::File(path));
        }
    }
    Ok(Location::System)
}

/// `OIDNProgressMonitorFunction`: called by OIDN during a filter's execution with the user
/// pointer and the fraction done; returning `false` cancels the execution.
pub(super) type ProgressMonitor = unsafe extern "C" fn(*mut c_void, f64) -> bool;

/// OIDN's C entry points this crate calls (OIDN 2.x, `oidn.h`), resolved from the opened library.
pub(super) struct Api {
    pub new_device: unsafe extern "C" fn(c_int) -> *mut c_void,
    pub commit_device: unsafe extern "C" fn(*mut c_void),
    pub release_device: unsafe extern "C" fn(*mut c_void),
    pub get_device_error: unsafe extern "C" fn(*mut c_void, *mut *const c_char) -> c_int,
    pub get_device_int: unsafe extern "C" fn(*mut c_void, *const c_char) -> c_int,
    pub new_filter: unsafe extern "C" fn(*mut c_void, *const c_char) -> *mut c_void,
    #[allow(clippy::type_complexity, reason = "the C signature, one pointer type")]
    pub set_shared_filter_image: unsafe extern "C" fn(
        *mut c_void,
        *const c_char,
        *mut c_void,
        c_int,
        usize,
        usize,
        usize,
        usize,
        usize,
    ),
    pub set_filter_bool: unsafe extern "C" fn(*mut c_void, *const c_char, bool),
    pub set_filter_int: unsafe extern "C" fn(*mut c_void, *const c_char, c_int),
    pub commit_filter: unsafe extern "C" fn(*mut c_void),
    pub execute_filter: unsafe extern "C" fn(*mut c_void),
    pub set_filter_progress_monitor_function:
        unsafe extern "C" fn(*mut c_void, Option<ProgressMonitor>, *mut c_void),
    pub release_filter: unsafe extern "C" fn(*mut c_void),
    /// Where the library was opened from, for messages and the EXR header.
    pub origin: String,
    /// Kept open for as long as the function pointers above are used.
    _library: libloading::Library,
}

impl Api {
    /// Opens the library by the rules above (reading `MCCTRACE_OIDN` and the current directory)
    /// and resolves every entry point.
    pub fn open() -> Result<Self, DenoiseError> {
        let env = std::env::var_os(ENV_VAR).filter(|v| !v.is_empty()).map(PathBuf::from);
        let cwd = std::env::current_dir().unwrap_or_default();
        let location = find_library(env.as_deref(), &cwd)?;
        let (library, origin) = match &location {
            // SAFETY: opening OIDN runs its library initialisers, which only register its
            // devices; nothing else in the process is touched.
            Location::File(path) => (unsafe { libloading::Library::new(path) }, path.display().to_string()),
            // SAFETY: as above, for the copy the system's loader finds.
            Location::System => (unsafe { libloading::Library::new(LIB_NAME) }, LIB_NAME.to_owned()),
        };
        let library = library.map_err(|e| match location {
            Location::System => DenoiseError::NotFound {
                looked: format!(
                    "{ENV_VAR} (unset), .venv/lib/python*/site-packages/pyoidn/oidn/lib/ here, the \
                     system's libraries ({e})"
                ),
            },
            Location::File(path) => DenoiseError::Load { path, message: e.to_string() },
        })?;
        macro_rules! symbol {
            ($name:literal) => {
                // SAFETY: the symbol is OIDN 2.x's C function of this name, whose signature
                // (`oidn.h`) the field's type repeats; the library stays open in `_library`.
                *unsafe { library.get(concat!($name, "\0").as_bytes()) }.map_err(|e| DenoiseError::Load {
                    path: PathBuf::from(&origin),
                    message: format!("{}: {e} (not OIDN 2.x?)", $name),
                })?
            };
        }
        Ok(Self {
            new_device: symbol!("oidnNewDevice"),
            commit_device: symbol!("oidnCommitDevice"),
            release_device: symbol!("oidnReleaseDevice"),
            get_device_error: symbol!("oidnGetDeviceError"),
            get_device_int: symbol!("oidnGetDeviceInt"),
            new_filter: symbol!("oidnNewFilter"),
            set_shared_filter_image: symbol!("oidnSetSharedFilterImage"),
            set_filter_bool: symbol!("oidnSetFilterBool"),
            set_filter_int: symbol!("oidnSetFilterInt"),
            commit_filter: symbol!("oidnCommitFilter"),
            execute_filter: symbol!("oidnExecuteFilter"),
            set_filter_progress_monitor_function: symbol!("oidnSetFilterProgressMonitorFunction"),
            release_filter: symbol!("oidnReleaseFilter"),
            origin,
            _library: library,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rules in order: the variable decides alone (a wrong one is refused, naming it), then
    /// the project's `.venv`, then the system's loader.
    #[test]
    fn the_library_is_looked_for_by_the_documented_rules() {
        let dir = std::env::temp_dir().join(format!("mcctrace-oidn-find-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        assert_eq!(find_library(None, &dir).unwrap(), Location::System);
        let lib = dir.join(".venv/lib/python3.11/site-packages/pyoidn/oidn/lib");
        std::fs::create_dir_all(&lib).unwrap();
        std::fs::write(lib.join(LIB_NAME), b"").unwrap();
        assert_eq!(find_library(None, &dir).unwrap(), Location::File(lib.join(LIB_NAME)));
        let oidn = lib.parent().unwrap();
        for given in [oidn, lib.as_path(), lib.join(LIB_NAME).as_path()] {
            assert_eq!(find_library(Some(given), &dir).unwrap(), Location::File(lib.join(LIB_NAME)));
        }
        let wrong = dir.join("nowhere");
        let message = find_library(Some(&wrong), &dir).unwrap_err().to_string();
        assert!(message.contains("MCCTRACE_OIDN") && message.contains("nowhere"), "{message}");
        assert!(message.contains(INSTALL_COMMAND), "{message}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
