//! [`Geoms`]: which geoms a sheet draws, as the geom groups and the option's group flags a
//! face sets on its MuJoCo before drawing.

use std::fmt;
use std::str::FromStr;

use crate::error::{Error, ErrorKind};

/// Which geoms are drawn. Sites are never drawn (every `sitegroup` off): they are markers,
/// not the scene.
///
/// ```
/// use mjcf_forge::sheet::Geoms;
///
/// assert_eq!("collision".parse::<Geoms>(), Ok(Geoms::Collision));
/// assert_eq!(Geoms::default().to_string(), "default");
/// let unknown = "nope".parse::<Geoms>().unwrap_err();
/// assert_eq!(unknown.kind, mjcf_forge::ErrorKind::UnknownGeoms("nope".into()));
/// assert_eq!(unknown.to_string(), "unknown geom set 'nope' (default, visual, collision, all)");
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Geoms {
    /// As MuJoCo draws a model by default: the geoms of groups 0, 1 and 2.
    #[default]
    Default,
    /// The geoms that do not collide (`contype` and `conaffinity` 0), in any group, and
    /// every geom of a body that has no such geom (so no body disappears).
    Visual,
    /// The geoms that collide (`contype` or `conaffinity` not 0), in any group.
    Collision,
    /// Every geom of every group.
    All,
}

/// What a face sets on its MuJoCo to draw a [`Geoms`] (see [`Geoms::choose`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GeomChoice {
    /// Each geom's group for the drawing (`geom_group`, restored afterwards): 0 for a
    /// geom drawn, the last group for one hidden; `None` leaves the groups as compiled.
    pub groups: Option<Vec<i32>>,
    /// Which geom groups are drawn (`mjvOption.geomgroup`); `None` leaves MuJoCo's default
    /// option (groups 0, 1 and 2).
    pub groups_on: Option<Vec<bool>>,
}

impl Geoms {
    /// Every value, in declaration order.
    pub const ALL: [Geoms; 4] = [Geoms::Default, Geoms::Visual, Geoms::Collision, Geoms::All];

    /// Its name on the command line and in Python: `default`, `visual`, `collision`, `all`.
    pub fn as_str(self) -> &'static str {
        match self {
            Geoms::Default => "default",
            Geoms::Visual => "visual",
            Geoms::Collision => "collision",
            Geoms::All => "all",
        }
    }

    /// The groups and group flags that draw this set: the geoms kept put in group 0 and the
    /// others in the last of `ngroup` groups (MuJoCo's `mjNGROUP`), only group 0 drawn;
    /// [`Geoms::All`] draws every group as compiled, [`Geoms::Default`] changes nothing.
    /// Per geom `g`: whether it collides (`contype[g] != 0 || conaffinity[g] != 0`) and its
    /// body (`geom_bodyid[g]`, below `nbody`).
    ///
    /// ```
    /// use mjcf_forge::sheet::Geoms;
    ///
    /// // Body 1: a collision geom and a visual one; body 2: a collision geom only.
    /// let (collides, bodies) = ([true, false, true], [1, 1, 2]);
    /// let visual = Geoms::Visual.choose(&collides, &bodies, 3, 6);
    /// assert_eq!(visual.groups, Some(vec![5, 0, 0]));
    /// assert_eq!(visual.groups_on, Some(vec![true, false, false, false, false, false]));
    /// assert_eq!(Geoms::Collision.choose(&collides, &bodies, 3, 6).groups, Some(vec![0, 5, 0]));
    /// assert_eq!(Geoms::All.choose(&collides, &bodies, 3, 6).groups, None);
    /// assert_eq!(Geoms::Default.choose(&collides, &bodies, 3, 6).groups_on, None);
    /// ```
    pub fn choose(
        self,
        collides: &[bool],
        bodies: &[i32],
        nbody: usize,
        ngroup: usize,
    ) -> GeomChoice {
        let last = i32::try_from(ngroup.saturating_sub(1)).unwrap_or(i32::MAX);
        let only_first = || Some((0..ngroup).map(|i| i == 0).collect());
        let body = |g: usize| usize::try_from(bodies[g]).ok().filter(|b| *b < nbody);
        let keep: Vec<bool> = match self {
            Geoms::Default => {
                return GeomChoice {
                    groups: None,
                    groups_on: None,
                };
            }
            Geoms::All => {
                return GeomChoice {
                    groups: None,
                    groups_on: Some(vec![true; ngroup]),
                };
            }
            Geoms::Collision => collides.to_vec(),
            Geoms::Visual => {
                let mut has_visual = vec![false; nbody];
                for g in (0..collides.len()).filter(|&g| !collides[g]) {
                    if let Some(b) = body(g) {
                        has_visual[b] = true;
                    }
                }
                (0..collides.len())
                    .map(|g| !collides[g] || !body(g).is_some_and(|b| has_visual[b]))
                    .collect()
            }
        };
        GeomChoice {
            groups: Some(keep.iter().map(|k| if *k { 0 } else { last }).collect()),
            groups_on: only_first(),
        }
    }
}

impl fmt::Display for Geoms {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl FromStr for Geoms {
    type Err = Error;

    fn from_str(s: &str) -> Result<Geoms, Error> {
        Geoms::ALL
            .into_iter()
            .find(|g| g.as_str() == s)
            .ok_or_else(|| Error::bare(ErrorKind::UnknownGeoms(s.to_owned())))
    }
}
