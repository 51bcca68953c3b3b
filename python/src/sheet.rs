//! The sheet tier's face: the contact sheet's rules (`mjcf_forge::sheet`), which
//! `mjcf_forge/_preview.py` runs around the user's `mujoco.Renderer`: where each cell goes,
//! its label, the PNG, the free camera's framing and the geom sets. The same rules the
//! command line's `mjcf-forge preview` runs over the linked MuJoCo.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::pybacked::PyBackedBytes;
use pyo3::types::{PyBytes, PyTuple};

use mjcf_forge::sheet::{
    FramedGeom, FreeCamera, GAP, GAP_COLOR, Geoms, Image, Layout, draw_label, label_scale,
};

/// Where each cell of a contact sheet of ``n`` cells of ``cell_width`` x ``cell_height``
/// goes, ``columns`` per row (by default the smallest number whose square holds them).
#[pyclass(name = "SheetLayout", module = "mjcf_forge._mjcf_forge", frozen)]
pub(crate) struct PySheetLayout(Layout);

#[pymethods]
impl PySheetLayout {
    #[new]
    #[pyo3(signature = (n, cell_width, cell_height, columns = None))]
    fn new(n: usize, cell_width: u32, cell_height: u32, columns: Option<u32>) -> PyResult<Self> {
        if n == 0 || cell_width == 0 || cell_height == 0 {
            return Err(PyValueError::new_err(
                "a sheet needs at least one cell of at least one pixel",
            ));
        }
        Ok(PySheetLayout(Layout::new(
            n,
            cell_width,
            cell_height,
            columns,
        )))
    }

    /// Cells per row.
    #[getter]
    fn columns(&self) -> u32 {
        self.0.columns
    }

    /// Rows.
    #[getter]
    fn rows(&self) -> u32 {
        self.0.rows
    }

    /// The sheet's width in pixels.
    #[getter]
    fn width(&self) -> u32 {
        self.0.width()
    }

    /// The sheet's height in pixels.
    #[getter]
    fn height(&self) -> u32 {
        self.0.height()
    }

    /// The top left corner ``(x, y)`` of cell ``k``.
    fn origin(&self, k: usize) -> (u32, u32) {
        self.0.cell_origin(k)
    }
}

/// A contact sheet being filled: the gap colour until cells are placed.
#[pyclass(name = "ContactSheet", module = "mjcf_forge._mjcf_forge")]
pub(crate) struct PyContactSheet {
    layout: Layout,
    image: Image,
}

#[pymethods]
impl PyContactSheet {
    #[new]
    fn new(layout: &Bound<'_, PySheetLayout>) -> Self {
        let layout = layout.get().0;
        PyContactSheet {
            layout,
            image: Image::new(layout.width(), layout.height(), GAP_COLOR),
        }
    }

    /// Cell ``k``'s pixels (RGB, top row first, the layout's cell size), labelled with
    /// ``label`` in its top left corner when given.
    #[pyo3(signature = (k, pixels, label = None))]
    fn place(&mut self, k: usize, pixels: PyBackedBytes, label: Option<&str>) -> PyResult<()> {
        let (w, h) = (self.layout.cell_width, self.layout.cell_height);
        let mut cell = Image::from_rgb(w, h, pixels.to_vec())
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        if let Some(label) = label {
            draw_label(&mut cell, label, label_scale(w, h));
        }
        let (x, y) = self.layout.cell_origin(k);
        self.image.blit(&cell, x, y);
        Ok(())
    }

    /// The sheet's pixels: RGB, top row first.
    fn rgb<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        PyBytes::new(py, &self.image.rgb)
    }

    /// The sheet as a PNG file's bytes (8-bit RGB, unfiltered rows).
    fn png<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let image = &self.image;
        let bytes = crate::errors::run(py, || Ok(image.to_png()?))?;
        Ok(PyBytes::new(py, &bytes))
    }
}

/// The sheet's free camera, ``(x, y, z, distance, azimuth, elevation)``, from
/// ``mjv_defaultFreeCamera``'s six numbers, the geoms' bodies, whether each is a plane,
/// their positions at ``qpos0`` (3 each) and bounding radii, and ``vis.global_.fovy``
/// (``mjcf_forge::sheet::FreeCamera::framing``).
#[pyfunction]
fn sheet_free_camera(
    default: [f64; 6],
    body: Vec<i64>,
    plane: Vec<bool>,
    xpos: Vec<f64>,
    rbound: Vec<f64>,
    fovy: f64,
) -> PyResult<[f64; 6]> {
    let n = body.len();
    if plane.len() != n || rbound.len() != n || xpos.len() != 3 * n {
        return Err(PyValueError::new_err(
            "sheet_free_camera: one body, plane flag, 3 coordinates and radius per geom",
        ));
    }
    let geoms = (0..n).map(|g| FramedGeom {
        body: body[g],
        plane: plane[g],
        pos: [xpos[3 * g], xpos[3 * g + 1], xpos[3 * g + 2]],
        rbound: rbound[g],
    });
    Ok(FreeCamera::framing(FreeCamera::from_array(default), geoms, fovy).to_array())
}

/// Each geom's group (or None) and the groups drawn (or None).
type GroupsAndFlags = (Option<Vec<i32>>, Option<Vec<bool>>);

/// What drawing the geom set ``geoms`` sets: each geom's group (or None: as compiled)
/// and which of ``ngroup`` groups are drawn (or None: MuJoCo's default option), from
/// whether each geom collides and its body (``mjcf_forge::sheet::Geoms::choose``).
#[pyfunction]
fn sheet_geom_groups(
    geoms: &str,
    collides: Vec<bool>,
    body: Vec<i32>,
    nbody: usize,
    ngroup: usize,
) -> PyResult<GroupsAndFlags> {
    let set: Geoms = geoms
        .parse()
        .map_err(|e: mjcf_forge::Error| PyValueError::new_err(e.to_string()))?;
    if body.len() != collides.len() {
        return Err(PyValueError::new_err(
            "sheet_geom_groups: one collision flag and one body per geom",
        ));
    }
    let choice = set.choose(&collides, &body, nbody, ngroup);
    Ok((choice.groups, choice.groups_on))
}

/// Adds the sheet's rules to the module.
pub(crate) fn add(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("SHEET_GAP", GAP)?;
    let [r, g, b] = GAP_COLOR;
    m.add("SHEET_GAP_COLOR", (r, g, b))?;
    let names: Vec<&str> = Geoms::ALL.iter().map(|g| g.as_str()).collect();
    m.add("SHEET_GEOMS", PyTuple::new(m.py(), names)?)?;
    m.add_class::<PySheetLayout>()?;
    m.add_class::<PyContactSheet>()?;
    m.add_function(wrap_pyfunction!(sheet_free_camera, m)?)?;
    m.add_function(wrap_pyfunction!(sheet_geom_groups, m)?)?;
    Ok(())
}
