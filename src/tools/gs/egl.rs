//! A headless OpenGL context through EGL, with no window and no surface: libEGL is loaded at
//! run time (so a machine without it only loses the `gs` method), displays are taken from
//! the EGL device platform (a GPU without a display server), Mesa's surfaceless platform,
//! then the default display, and a hardware renderer is preferred over a software one.

use crate::error::{Error, Result};
use khronos_egl as egl;
use std::ffi::c_void;
use std::sync::{Arc, OnceLock};

type Egl = egl::DynamicInstance<egl::EGL1_4>;

const PLATFORM_DEVICE: egl::Enum = 0x313F;
const PLATFORM_SURFACELESS_MESA: egl::Enum = 0x31DD;

/// The least OpenGL the method needs: geometry shaders (3.2), timer queries and explicit
/// attribute locations (3.3).
pub const GL_VERSION: (i32, i32) = (3, 3);

/// Names the libEGL to load instead of the system's (a vendor's own, say).
pub const LIBRARY_VARIABLE: &str = "WIREPASS_EGL_LIBRARY";

/// Renderer names of software rasterizers: chosen only where nothing else answers.
const SOFTWARE: [&str; 4] = ["llvmpipe", "softpipe", "swrast", "SwiftShader"];

/// The display the process draws on, chosen once.
struct Chosen {
    egl: Arc<Egl>,
    /// `EGLDisplay` and `EGLConfig` (null: EGL_KHR_no_config_context), as addresses so that
    /// the choice can be shared between threads; EGL handles are process-wide.
    display: usize,
    config: usize,
}

fn chosen() -> std::result::Result<&'static Chosen, String> {
    static CHOSEN: OnceLock<std::result::Result<Chosen, String>> = OnceLock::new();
    CHOSEN.get_or_init(choose).as_ref().map_err(Clone::clone)
}

/// Every display that gives an OpenGL core context, the first hardware one kept (else the
/// first). Displays are initialised and never terminated: another thread may draw on one.
fn choose() -> std::result::Result<Chosen, String> {
    // SAFETY: loads the system's libEGL (or the one named); its symbols are checked by the
    // loader.
    let loaded = match std::env::var_os(LIBRARY_VARIABLE) {
        Some(path) => unsafe { Egl::load_required_from_filename(&path) }
            .map_err(|e| format!("{LIBRARY_VARIABLE}={}: {e}", path.to_string_lossy())),
        None => {
            unsafe { Egl::load_required() }.map_err(|e| format!("no libEGL could be loaded ({e})"))
        }
    };
    let egl = Arc::new(loaded?);
    let client = egl
        .query_string(None, egl::EXTENSIONS)
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut candidates = Vec::new();
    if let Some(egl15) = egl.upcast::<egl::EGL1_5>() {
        if client.contains("EGL_EXT_platform_device") {
            for device in devices(&egl) {
                // SAFETY: `device` came from eglQueryDevicesEXT.
                if let Ok(d) = unsafe {
                    egl15.get_platform_display(PLATFORM_DEVICE, device, &[egl::ATTRIB_NONE])
                } {
                    candidates.push(d);
                }
            }
        }
        if client.contains("EGL_MESA_platform_surfaceless") {
            // SAFETY: the surfaceless platform takes the default display.
            if let Ok(d) = unsafe {
                egl15.get_platform_display(
                    PLATFORM_SURFACELESS_MESA,
                    egl::DEFAULT_DISPLAY,
                    &[egl::ATTRIB_NONE],
                )
            } {
                candidates.push(d);
            }
        }
    }
    // SAFETY: the default display needs no native handle.
    if let Some(d) = unsafe { egl.get_display(egl::DEFAULT_DISPLAY) } {
        candidates.push(d);
    }
    let mut reasons = Vec::new();
    let mut first = None;
    for display in candidates {
        match probe(&egl, display) {
            Ok((config, renderer)) => {
                let pick = Chosen {
                    egl: egl.clone(),
                    display: display.as_ptr() as usize,
                    config,
                };
                if !is_software(&renderer) {
                    return Ok(pick);
                }
                first.get_or_insert(pick);
            }
            Err(e) => reasons.push(e),
        }
    }
    first.ok_or_else(|| {
        if reasons.is_empty() {
            "libEGL offers no display".to_owned()
        } else {
            reasons.join("; ")
        }
    })
}

/// Whether `renderer` (GL_RENDERER) names a software rasterizer.
pub fn is_software(renderer: &str) -> bool {
    SOFTWARE.iter().any(|s| renderer.contains(s))
}

/// The EGL devices (EGL_EXT_device_enumeration), GPUs first as the driver lists them.
fn devices(egl: &Egl) -> Vec<*mut c_void> {
    type QueryDevices = unsafe extern "system" fn(i32, *mut *mut c_void, *mut i32) -> u32;
    let Some(f) = egl.get_proc_address("eglQueryDevicesEXT") else {
        return Vec::new();
    };
    // SAFETY: eglQueryDevicesEXT has this signature (EGL_EXT_device_enumeration).
    let query: QueryDevices = unsafe { std::mem::transmute(f) };
    let mut list = vec![std::ptr::null_mut(); 16];
    let mut count = 0;
    // SAFETY: `list` holds 16 entries.
    if unsafe { query(16, list.as_mut_ptr(), &mut count) } != egl::TRUE {
        return Vec::new();
    }
    list.truncate(count.clamp(0, 16) as usize);
    list
}

/// Initialises `display`, makes an OpenGL core context current on it and reads the
/// renderer's name: the config to create contexts with, and that name.
fn probe(egl: &Arc<Egl>, display: egl::Display) -> std::result::Result<(usize, String), String> {
    let (major, minor) = egl
        .initialize(display)
        .map_err(|e| format!("eglInitialize: {e}"))?;
    if (major, minor) < (1, 4) {
        return Err(format!("EGL {major}.{minor} is older than 1.4"));
    }
    let context = Context::create(egl, display, None)?;
    let gl = context.load();
    use glow::HasContext;
    // SAFETY: the context is current on this thread.
    let renderer = unsafe { gl.get_parameter_string(glow::RENDERER) };
    Ok((context.config, renderer))
}

/// An OpenGL core context of [`GL_VERSION`] or later, current on the thread that made it
/// until it is dropped.
pub struct Context {
    egl: Arc<Egl>,
    display: egl::Display,
    context: egl::Context,
    config: usize,
    /// Current on this thread only.
    _thread: std::marker::PhantomData<*const ()>,
}

impl Context {
    /// A context on the process's chosen display, current on this thread.
    pub fn new() -> Result<Context> {
        let c = chosen().map_err(no_context)?;
        // SAFETY: the address is of a display `choose` initialised and never terminates.
        let display = unsafe { egl::Display::from_ptr(c.display as *mut c_void) };
        Context::create(&c.egl, display, Some(c.config)).map_err(no_context)
    }

    fn create(
        egl: &Arc<Egl>,
        display: egl::Display,
        config: Option<usize>,
    ) -> std::result::Result<Context, String> {
        egl.bind_api(egl::OPENGL_API)
            .map_err(|e| format!("eglBindAPI(OpenGL): {e}"))?;
        let config = match config {
            Some(c) => c,
            None => egl
                .choose_first_config(
                    display,
                    &[
                        egl::RENDERABLE_TYPE,
                        egl::OPENGL_BIT,
                        egl::SURFACE_TYPE,
                        0,
                        egl::NONE,
                    ],
                )
                .map_err(|e| format!("eglChooseConfig: {e}"))?
                .map_or(0, |c| c.as_ptr() as usize),
        };
        let attributes = [
            egl::CONTEXT_MAJOR_VERSION,
            GL_VERSION.0,
            egl::CONTEXT_MINOR_VERSION,
            GL_VERSION.1,
            egl::CONTEXT_OPENGL_PROFILE_MASK,
            egl::CONTEXT_OPENGL_CORE_PROFILE_BIT,
            egl::NONE,
        ];
        // SAFETY: a config of this display, or null (EGL_KHR_no_config_context).
        let egl_config = unsafe { egl::Config::from_ptr(config as *mut c_void) };
        let context = egl
            .create_context(display, egl_config, None, &attributes)
            .map_err(|e| {
                format!(
                    "no OpenGL {}.{} core context: {e}",
                    GL_VERSION.0, GL_VERSION.1
                )
            })?;
        let made = Context {
            egl: egl.clone(),
            display,
            context,
            config,
            _thread: std::marker::PhantomData,
        };
        egl.make_current(display, None, None, Some(context))
            .map_err(|e| format!("eglMakeCurrent without a surface: {e}"))?;
        Ok(made)
    }

    /// Makes the context current on this thread (again).
    pub fn make_current(&self) -> Result<()> {
        self.egl
            .make_current(self.display, None, None, Some(self.context))
            .map_err(|e| Error::Device(format!("eglMakeCurrent: {e}")))
    }

    /// The context's OpenGL functions (the context must be current: it is on its thread).
    pub fn load(&self) -> glow::Context {
        let egl = &self.egl;
        // SAFETY: the context is current; functions are looked up by name in libEGL.
        unsafe {
            glow::Context::from_loader_function_cstr(|name| {
                name.to_str()
                    .ok()
                    .and_then(|n| egl.get_proc_address(n))
                    .map_or(std::ptr::null(), |f| f as *const c_void)
            })
        }
    }

    /// An OpenGL function glow does not wrap, by name.
    pub fn proc_address(&self, name: &str) -> Option<extern "system" fn()> {
        self.egl.get_proc_address(name)
    }
}

impl Drop for Context {
    fn drop(&mut self) {
        let _ = self.egl.make_current(self.display, None, None, None);
        let _ = self.egl.destroy_context(self.display, self.context);
    }
}

fn no_context(reason: String) -> Error {
    Error::NoAdapter(format!(
        "no OpenGL {}.{} core context for the geometry-shader method: {reason}",
        GL_VERSION.0, GL_VERSION.1
    ))
}
