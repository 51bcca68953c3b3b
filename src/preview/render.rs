//! [`Renderer`]: a headless OpenGL context and MuJoCo's renderer drawing one compiled model
//! into an [`Image`], from a [`Camera`], with the geoms [`Geoms`] picks.

use std::ffi::c_int;
use std::fmt;
use std::marker::PhantomData;
use std::ptr::NonNull;

use super::sys::{self, RawGl};
use crate::error::{Error, ErrorKind};
use crate::mujoco::{CompiledModel, ObjType};
use crate::sheet::{FramedGeom, FreeCamera, Geoms, Image, draw_label, label_scale};

/// `mjGEOM_PLANE` in `mjtGeom`.
const GEOM_PLANE: i32 = 0;

/// Where a render looks from.
///
/// ```
/// use std::path::Path;
/// use mjcf_forge::mujoco::compile_str;
/// use mjcf_forge::preview::Camera;
///
/// let model = compile_str(r#"<mujoco><worldbody><camera name="top" pos="0 0 2"/>
///   <geom size="0.1"/></worldbody></mujoco>"#, Path::new(".")).unwrap();
/// assert_eq!(Camera::named(&model, "top").unwrap(), Camera::Fixed(0));
/// let unknown = Camera::named(&model, "side").unwrap_err();
/// assert!(matches!(unknown.kind, mjcf_forge::ErrorKind::UnknownCamera { .. }));
/// assert_eq!(unknown.to_string(), "the model has no camera named 'side' (its cameras: top)");
/// let Camera::Free { distance, .. } = Camera::free(&model) else { unreachable!() };
/// assert!(distance > 0.0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Camera {
    /// A free camera, as MuJoCo's `mjvCamera` of type `mjCAMERA_FREE`.
    Free {
        /// The point looked at.
        lookat: [f64; 3],
        /// Its distance from the camera.
        distance: f64,
        /// Azimuth in degrees.
        azimuth: f64,
        /// Elevation in degrees.
        elevation: f64,
    },
    /// The model's camera of this id.
    Fixed(usize),
}

impl Camera {
    /// The free camera that frames `model`'s bodies at its initial pose (`qpos0`): from
    /// the azimuth and elevation MuJoCo's viewer starts with (`mjv_defaultFreeCamera`,
    /// i.e. `<visual><global azimuth elevation>`), looking at the centre of the bounding
    /// box of every geom of a body other than the world (floors, walls and any geom of the
    /// world body left out, and planes), from the distance at which the sphere around that
    /// box fits the vertical field of view (`<visual><global fovy>`). A model whose geoms
    /// all belong to the world gets `mjv_defaultFreeCamera` unchanged (the statistic
    /// `center`, 1.5 `extent`s away). The rule is the sheet's ([`FreeCamera::framing`]),
    /// which Python's `Scene.preview` runs too; this reads its inputs from the model.
    pub fn free(model: &CompiledModel) -> Camera {
        let inputs = sys::sheet_inputs(model.raw(), model.sizes().ngeom, true);
        let default = FreeCamera::from_array(inputs.default_cam);
        let cam = match &inputs.xpos {
            Some(xpos) => {
                let geoms = (model.geom_bodyid().iter().zip(model.geom_type()))
                    .zip(xpos.iter().zip(&inputs.rbound))
                    .map(|((&body, &kind), (&pos, &rbound))| FramedGeom {
                        body: i64::from(body),
                        plane: kind == GEOM_PLANE,
                        pos,
                        rbound,
                    });
                FreeCamera::framing(default, geoms, inputs.fovy)
            }
            None => default,
        };
        Camera::Free {
            lookat: cam.lookat,
            distance: cam.distance,
            azimuth: cam.azimuth,
            elevation: cam.elevation,
        }
    }

    /// The model's camera named `name` (its full name, prefix included).
    pub fn named(model: &CompiledModel, name: &str) -> Result<Camera, Error> {
        let names = model.names(ObjType::Camera);
        names
            .iter()
            .position(|n| n == name)
            .map(Camera::Fixed)
            .ok_or_else(|| {
                Error::bare(ErrorKind::UnknownCamera {
                    name: name.to_owned(),
                    cameras: names.into_iter().filter(|n| !n.is_empty()).collect(),
                })
            })
    }
}

/// A headless OpenGL context, current on the thread that made it, with which MuJoCo's own
/// renderer (`mjv_updateScene`, `mjr_render`) draws compiled models into memory.
///
/// The context is EGL's (`libEGL.so.1`: a device display, else Mesa's surfaceless
/// platform, else the default display), else OSMesa's (`libOSMesa.so`), both opened at
/// run time; the environment variable `MUJOCO_GL` set to `egl` or `osmesa` allows only
/// that one. A renderer stays on its thread (it is neither `Send` nor `Sync`); two
/// renderers on one thread would take each other's context.
///
/// ```no_run
/// use std::path::Path;
/// use mjcf_forge::mujoco::compile_str;
/// use mjcf_forge::preview::{Camera, Geoms, Renderer};
///
/// let mut model = compile_str("<mujoco><worldbody><geom size='0.1'/></worldbody></mujoco>",
///                             Path::new(".")).unwrap();
/// let mut renderer = Renderer::new(320, 240).unwrap();
/// let camera = Camera::free(&model);
/// let image = renderer.render(&mut model, camera, Geoms::Default, Some("0")).unwrap();
/// assert_eq!((image.width, image.height), (320, 240));
/// ```
pub struct Renderer {
    gl: NonNull<RawGl>,
    width: u32,
    height: u32,
    /// Bound to its thread: the context is current there only.
    _not_send: PhantomData<*mut ()>,
}

impl fmt::Debug for Renderer {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Renderer")
            .field("backend", &self.backend())
            .field("width", &self.width)
            .field("height", &self.height)
            .finish()
    }
}

impl Drop for Renderer {
    fn drop(&mut self) {
        // SAFETY: made by `gl_new`, freed once, here.
        unsafe { sys::gl_free(self.gl) }
    }
}

/// The largest image side drawn (MuJoCo's offscreen buffers; GL drivers allow more, but a
/// contact sheet cell needs no more).
pub const MAX_SIDE: u32 = 4096;

impl Renderer {
    /// A context for images of `width` x `height` pixels (1 to [`MAX_SIDE`] each), made
    /// current on this thread; the error names every backend tried and why it failed.
    pub fn new(width: u32, height: u32) -> Result<Renderer, Error> {
        check_size(width, height)?;
        let backend = match std::env::var("MUJOCO_GL").ok().as_deref().map(str::trim) {
            Some(v) if v.eq_ignore_ascii_case("egl") => 1,
            Some(v) if v.eq_ignore_ascii_case("osmesa") => 2,
            _ => 0,
        };
        let gl = sys::gl_new(backend, width as c_int, height as c_int).map_err(|why| {
            invalid(format!(
                "cannot create a headless OpenGL context: {why} (docs/install.md, \"Rendering\")"
            ))
        })?;
        Ok(Renderer {
            gl,
            width,
            height,
            _not_send: PhantomData,
        })
    }

    /// The OpenGL platform in use: `"egl"` or `"osmesa"`.
    pub fn backend(&self) -> &'static str {
        sys::gl_kind(self.gl)
    }

    /// `model` at its initial pose (`qpos0`) drawn from `camera`, with `label` in the top
    /// left corner (the sheet's bitmap digits, [`draw_label`], as Python's `Scene.preview`
    /// draws them); sites are not drawn. The model's visual
    /// settings and geom groups are changed for the render and restored before this
    /// returns, hence `&mut`.
    pub fn render(
        &mut self,
        model: &mut CompiledModel,
        camera: Camera,
        geoms: Geoms,
        label: Option<&str>,
    ) -> Result<Image, Error> {
        let (rgb, _) = self.run(model, camera, geoms, false)?;
        let mut image = Image::from_bottom_up(self.width, self.height, rgb);
        if let Some(label) = label {
            draw_label(&mut image, label, label_scale(self.width, self.height));
        }
        Ok(image)
    }

    /// Segmentation: for each pixel (top row first, `width * height` of them) the id of
    /// the geom drawn there, `-1` where none is; drawn as [`Renderer::render`] draws
    /// (without multisampling, whose blended edges would be other ids).
    pub fn segment(
        &mut self,
        model: &mut CompiledModel,
        camera: Camera,
        geoms: Geoms,
    ) -> Result<Vec<i32>, Error> {
        let (_, seg) = self.run(model, camera, geoms, true)?;
        let row = self.width as usize;
        Ok(seg.chunks(row.max(1)).rev().flatten().copied().collect())
    }

    fn run(
        &mut self,
        model: &mut CompiledModel,
        camera: Camera,
        geoms: Geoms,
        segment: bool,
    ) -> Result<(Vec<u8>, Vec<i32>), Error> {
        let (free_cam, camid) = match camera {
            Camera::Free {
                lookat,
                distance,
                azimuth,
                elevation,
            } => (
                [
                    lookat[0], lookat[1], lookat[2], distance, azimuth, elevation,
                ],
                -1,
            ),
            Camera::Fixed(id) => {
                let ncam = model.sizes().ncam;
                if id >= ncam {
                    return Err(invalid(format!(
                        "camera id {id} is out of range (the model has {ncam} cameras)"
                    )));
                }
                ([0.0; 6], id as c_int)
            }
        };
        let sizes = model.sizes();
        let inputs = sys::sheet_inputs(model.raw(), sizes.ngeom, false);
        let choice = geoms.choose(
            &inputs.collides,
            model.geom_bodyid(),
            sizes.nbody,
            inputs.ngroup,
        );
        let job = sys::Job {
            width: self.width as c_int,
            height: self.height as c_int,
            free_cam,
            camid,
            groups: choice.groups,
            groups_on: choice
                .groups_on
                .map(|on| on.into_iter().map(c_int::from).collect()),
            segment,
        };
        // Another renderer on this thread may have taken the context since.
        if !sys::gl_make_current(self.gl) {
            return Err(invalid("cannot make the OpenGL context current".to_owned()));
        }
        // SAFETY: `&mut model` is exclusive for the call, and this renderer's context is
        // current on this thread (the type is neither Send nor Sync).
        unsafe { sys::render(model.as_mut_ptr(), &job) }.map_err(invalid)
    }
}

fn check_size(width: u32, height: u32) -> Result<(), Error> {
    if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE {
        return Err(invalid(format!(
            "image size {width}x{height}: each side must be 1 to {MAX_SIDE} pixels"
        )));
    }
    Ok(())
}

pub(super) fn invalid(message: String) -> Error {
    Error {
        location: None,
        kind: ErrorKind::Invalid(message),
    }
}
