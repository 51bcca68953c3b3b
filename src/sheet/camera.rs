//! The sheet's free camera: the rule that frames a model's bodies, as arithmetic over the
//! values a face reads from its MuJoCo (the default free camera, the geoms at `qpos0`, the
//! field of view).

/// A free camera, as MuJoCo's `mjvCamera` of type `mjCAMERA_FREE`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FreeCamera {
    /// The point looked at.
    pub lookat: [f64; 3],
    /// Its distance from the camera.
    pub distance: f64,
    /// Azimuth in degrees.
    pub azimuth: f64,
    /// Elevation in degrees.
    pub elevation: f64,
}

/// What the framing reads of one geom of the compiled model at `qpos0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FramedGeom {
    /// Its body's id (`geom_bodyid`); the world's (0) are left out.
    pub body: i64,
    /// Whether it is a plane (`mjGEOM_PLANE`), left out: a floor is infinite.
    pub plane: bool,
    /// Its position in the world (`geom_xpos` after `mj_kinematics`).
    pub pos: [f64; 3],
    /// The radius of its bounding sphere (`geom_rbound`).
    pub rbound: f64,
}

impl FreeCamera {
    /// The camera that frames the geoms of every body other than the world: from
    /// `default`'s azimuth and elevation (`mjv_defaultFreeCamera`, i.e.
    /// `<visual><global azimuth elevation>`), looking at the centre of the box that holds
    /// every such geom's bounding sphere, from the distance at which the sphere around that
    /// box fits the vertical field of view `fovy` (degrees, `<visual><global fovy>`).
    /// Without such geoms, `default` unchanged (the statistic `center`, 1.5 `extent`s
    /// away).
    ///
    /// ```
    /// use mjcf_forge::sheet::{FramedGeom, FreeCamera};
    ///
    /// let default = FreeCamera { lookat: [0.0; 3], distance: 3.0, azimuth: 90.0, elevation: -45.0 };
    /// let floor = FramedGeom { body: 0, plane: true, pos: [0.0; 3], rbound: 0.0 };
    /// let ball = FramedGeom { body: 1, plane: false, pos: [1.0, 0.0, 0.5], rbound: 0.5 };
    /// let cam = FreeCamera::framing(default, [floor, ball], 90.0);
    /// assert_eq!(cam.lookat, [1.0, 0.0, 0.5]);
    /// assert!((cam.distance - 1.5f64.sqrt()).abs() < 1e-12);
    /// assert_eq!((cam.azimuth, cam.elevation), (90.0, -45.0));
    /// assert_eq!(FreeCamera::framing(default, [floor], 90.0), default);
    /// ```
    pub fn framing(
        default: FreeCamera,
        geoms: impl IntoIterator<Item = FramedGeom>,
        fovy: f64,
    ) -> FreeCamera {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        let mut found = false;
        for g in geoms {
            if g.body == 0 || g.plane {
                continue;
            }
            for k in 0..3 {
                lo[k] = lo[k].min(g.pos[k] - g.rbound);
                hi[k] = hi[k].max(g.pos[k] + g.rbound);
            }
            found = true;
        }
        let mut cam = default;
        if found {
            let mut half = 0.0;
            for k in 0..3 {
                cam.lookat[k] = (lo[k] + hi[k]) / 2.0;
                half += (hi[k] - lo[k]) * (hi[k] - lo[k]) / 4.0;
            }
            let radius = f64::sqrt(half);
            let s = f64::sin(fovy * std::f64::consts::PI / 360.0);
            if radius > 0.0 && s > 0.0 {
                cam.distance = radius / s;
            }
        }
        cam
    }

    /// The camera as six numbers: lookat (3), distance, azimuth, elevation.
    pub fn to_array(self) -> [f64; 6] {
        let [x, y, z] = self.lookat;
        [x, y, z, self.distance, self.azimuth, self.elevation]
    }

    /// The camera from [`FreeCamera::to_array`]'s six numbers.
    ///
    /// ```
    /// use mjcf_forge::sheet::FreeCamera;
    /// let six = [1.0, 2.0, 3.0, 4.0, 90.0, -45.0];
    /// assert_eq!(FreeCamera::from_array(six).to_array(), six);
    /// ```
    pub fn from_array(six: [f64; 6]) -> FreeCamera {
        FreeCamera {
            lookat: [six[0], six[1], six[2]],
            distance: six[3],
            azimuth: six[4],
            elevation: six[5],
        }
    }
}
