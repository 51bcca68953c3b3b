//! Contact sheets: variants of a scene compiled, rendered one per cell of a grid, each cell
//! labelled with its variant's index.

use rayon::prelude::*;

use super::render::{Camera, Renderer, invalid};
use crate::error::{Error, Errors};
use crate::mujoco::{CompiledModel, compile_document};
use crate::scene::{Params, Scene};
use crate::sheet::{GAP_COLOR, Geoms, Image, Layout};

/// How a contact sheet is drawn.
///
/// ```
/// use mjcf_forge::preview::{Geoms, SheetOptions};
///
/// let o = SheetOptions::default();
/// assert_eq!((o.cell_width, o.cell_height), (320, 240));
/// assert_eq!((o.columns, o.camera, o.geoms, o.labels), (None, None, Geoms::Default, true));
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SheetOptions {
    /// Width of a cell in pixels.
    pub cell_width: u32,
    /// Height of a cell in pixels.
    pub cell_height: u32,
    /// Cells per row; without it the smallest number whose square holds every cell
    /// (16 cells: 4, 8 cells: 3; see [`Layout::new`]).
    pub columns: Option<u32>,
    /// A camera of the scene, by its full name; without it, MuJoCo's default free camera
    /// of the first variant of the sheet, the same for every cell (see [`Camera::free`]).
    pub camera: Option<String>,
    /// Which geoms are drawn.
    pub geoms: Geoms,
    /// Each cell labelled with its variant's index in its top left corner
    /// ([`crate::sheet::draw_label`]).
    pub labels: bool,
}

impl Default for SheetOptions {
    fn default() -> Self {
        SheetOptions {
            cell_width: 320,
            cell_height: 240,
            columns: None,
            camera: None,
            geoms: Geoms::Default,
            labels: true,
        }
    }
}

/// A rendered contact sheet.
#[derive(Clone, Debug)]
pub struct Sheet {
    /// The whole sheet.
    pub image: Image,
    /// Where each cell is.
    pub layout: Layout,
    /// The variant of each cell, in order.
    pub indices: Vec<u64>,
    /// What was drawn for each cell's variant (its placed objects and their poses).
    pub params: Vec<Params>,
}

impl Sheet {
    /// Cell `k` of the sheet, as an image of its own.
    pub fn cell(&self, k: usize) -> Image {
        let (x, y) = self.layout.cell_origin(k);
        self.image
            .crop(x, y, self.layout.cell_width, self.layout.cell_height)
    }
}

/// Variants `indices` of `scene` (the same index may come twice) compiled with MuJoCo, in
/// parallel on the current rayon pool, with what was drawn for each.
fn compile_all(scene: &Scene, indices: &[u64]) -> Result<Vec<(CompiledModel, Params)>, Errors> {
    if indices.is_empty() {
        return Err(Errors(vec![invalid(format!(
            "{}: a contact sheet needs at least one variant",
            scene.file().display()
        ))]));
    }
    indices
        .par_iter()
        .map(|&i| {
            let v = scene.variant(i)?;
            let model = compile_document(&v.document).map_err(|e| Errors(vec![e]))?;
            Ok((model, v.params))
        })
        .collect()
}

/// The camera of a cell: the named one of its model, else `free`.
fn camera_of(
    scene: &Scene,
    index: u64,
    model: &CompiledModel,
    options: &SheetOptions,
    free: Camera,
) -> Result<Camera, Error> {
    match &options.camera {
        Some(name) => Camera::named(model, name).map_err(|why| {
            invalid(format!(
                "{}: variant {index}: {why}",
                scene.file().display()
            ))
        }),
        None => Ok(free),
    }
}

/// Renders variants `indices` of `scene` into a contact sheet with MuJoCo's renderer, on
/// this thread (variants are compiled in parallel on the current rayon pool first).
///
/// Every variant is drawn at its initial pose (`qpos0`): placed objects where they were
/// placed, joints at their reference positions. Without [`SheetOptions::camera`] all
/// cells share one free camera, MuJoCo's default one of the first index's model
/// ([`Camera::free`]), so that cells differ only where the variants do.
///
/// ```no_run
/// use mjcf_forge::preview::{SheetOptions, contact_sheet};
/// use mjcf_forge::scene::Scene;
///
/// let scene = Scene::demo()?;
/// let sheet = contact_sheet(&scene, &[0, 1, 2, 3], &SheetOptions::default())?;
/// sheet.image.write_png(std::path::Path::new("sheet.png"))?;
/// assert_eq!(sheet.layout.columns, 2);
/// # Ok::<(), mjcf_forge::Errors>(())
/// ```
pub fn contact_sheet(
    scene: &Scene,
    indices: &[u64],
    options: &SheetOptions,
) -> Result<Sheet, Errors> {
    let mut renderer = Renderer::new(options.cell_width, options.cell_height).map_err(one)?;
    let mut models = compile_all(scene, indices)?;
    let layout = Layout::new(
        indices.len(),
        options.cell_width,
        options.cell_height,
        options.columns,
    );
    let mut image = Image::new(layout.width(), layout.height(), GAP_COLOR);
    let free = Camera::free(&models[0].0);
    for (k, ((model, _), &index)) in models.iter_mut().zip(indices).enumerate() {
        let camera = camera_of(scene, index, model, options, free).map_err(one)?;
        let label = options.labels.then(|| index.to_string());
        let cell = renderer
            .render(model, camera, options.geoms, label.as_deref())
            .map_err(one)?;
        let (x, y) = layout.cell_origin(k);
        image.blit(&cell, x, y);
    }
    Ok(Sheet {
        image,
        layout,
        indices: indices.to_vec(),
        params: models.into_iter().map(|(_, p)| p).collect(),
    })
}

/// What [`contact_sheet`] draws in each cell, as segmentation: per cell, the id of the geom
/// at each of its pixels (top row first, `cell_width * cell_height` of them; `-1` where no
/// geom is), ids of that cell's variant's compiled model. For checking that what a sheet
/// shows is what was placed.
///
/// ```no_run
/// use mjcf_forge::preview::{SheetOptions, segment_cells};
/// use mjcf_forge::scene::Scene;
///
/// let scene = Scene::demo()?;
/// let cells = segment_cells(&scene, &[0, 1], &SheetOptions::default())?;
/// assert_eq!(cells[0].len(), 320 * 240);
/// # Ok::<(), mjcf_forge::Errors>(())
/// ```
pub fn segment_cells(
    scene: &Scene,
    indices: &[u64],
    options: &SheetOptions,
) -> Result<Vec<Vec<i32>>, Errors> {
    let mut renderer = Renderer::new(options.cell_width, options.cell_height).map_err(one)?;
    let mut models = compile_all(scene, indices)?;
    let free = Camera::free(&models[0].0);
    let mut cells = Vec::with_capacity(indices.len());
    for ((model, _), &index) in models.iter_mut().zip(indices) {
        let camera = camera_of(scene, index, model, options, free).map_err(one)?;
        cells.push(
            renderer
                .segment(model, camera, options.geoms)
                .map_err(one)?,
        );
    }
    Ok(cells)
}

fn one(e: Error) -> Errors {
    Errors(vec![e])
}
