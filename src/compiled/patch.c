// The MuJoCo side of patching a compiled model (src/compiled/cache.rs). Compiled by build.rs
// against the linked MuJoCo's own headers, as the FFI's shim is, so mjModel's and mjData's
// layouts are never copied into Rust: arrays are found by name through MuJoCo's X-macro
// table.
#include <stddef.h>
#include <string.h>

#include <mujoco/mujoco.h>

// A writable array of mjModel (MJMODEL_POINTERS), the size of its elements in bytes and
// how many elements it has; NULL and 0 when `name` is not one.
void* mjf_patch_array(mjModel* m, const char* name, size_t* elem_size, size_t* count) {
#undef MJ_M
#define MJ_M(n) m->n
#define X(type, field, nr, nc)                          \
  if (strcmp(name, #field) == 0) {                      \
    *elem_size = sizeof(type);                          \
    *count = (size_t)(m->nr) * (size_t)(nc);            \
    return (void*)m->field;                             \
  }
#define XNV X
  MJMODEL_POINTERS
#undef XNV
#undef X
#undef MJ_M
#define MJ_M(n) n
  *elem_size = 0;
  *count = 0;
  return NULL;
}

// The id of the element of `kind` ("body", "joint", "geom", "site", "camera", "light",
// "material", "actuator") named `name`; -1 when there is none.
int mjf_patch_name2id(const mjModel* m, const char* kind, const char* name) {
  static const struct { const char* name; int obj; } kinds[] = {
    {"body", mjOBJ_BODY},     {"joint", mjOBJ_JOINT}, {"geom", mjOBJ_GEOM},
    {"site", mjOBJ_SITE},     {"camera", mjOBJ_CAMERA}, {"light", mjOBJ_LIGHT},
    {"material", mjOBJ_MATERIAL}, {"actuator", mjOBJ_ACTUATOR},
  };
  for (size_t i = 0; i < sizeof(kinds) / sizeof(kinds[0]); i++) {
    if (strcmp(kinds[i].name, kind) == 0) return mj_name2id(m, kinds[i].obj, name);
  }
  return -1;
}

// A writable field of the model's mjOption (MJOPTION_FIELDS), the size of its elements in
// bytes and how many it has; NULL and 0 when `name` is not one.
void* mjf_patch_option(mjModel* m, const char* name, size_t* elem_size, size_t* count) {
#define X(type, field, n)                               \
  if (strcmp(name, #field) == 0) {                      \
    *elem_size = sizeof(type);                          \
    *count = (size_t)(n);                               \
    return (void*)&m->opt.field;                        \
  }
#define XVEC X
  MJOPTION_FIELDS
#undef XVEC
#undef X
  *elem_size = 0;
  *count = 0;
  return NULL;
}

mjData* mjf_patch_make_data(const mjModel* m) { return mj_makeData(m); }

void mjf_patch_delete_data(mjData* d) { mj_deleteData(d); }

// Bytes of a model's buffer and, when given, a data's buffer and arena.
long long mjf_patch_nbytes(const mjModel* m, const mjData* d) {
  long long n = (long long)m->nbuffer;
  if (d) n += (long long)d->nbuffer + (long long)d->narena;
  return n;
}

// The model's statistics: meaninertia, meanmass, meansize, extent, center[3].
void mjf_patch_get_stat(const mjModel* m, double out[7]) {
  out[0] = m->stat.meaninertia;
  out[1] = m->stat.meanmass;
  out[2] = m->stat.meansize;
  out[3] = m->stat.extent;
  out[4] = m->stat.center[0];
  out[5] = m->stat.center[1];
  out[6] = m->stat.center[2];
}

// The arrays mjcf_forge::split::statistics reads (src/split/statistics.rs), as
// compiled/statistics.rs declares them: positions of n rows have 3n numbers, the
// inertia's diagonal is at M_rowadr + M_rownnz - 1.
struct mjf_stat_arrays {
  const double *xpos, *xipos, *xanchor, *site_xpos, *geom_xpos, *geom_rbound, *geom_size,
      *hfield_size, *body_mass, *inertia;
  const int *geom_type, *geom_dataid, *body_parentid, *body_geomadr, *body_geomnum,
      *jnt_bodyid, *jnt_type, *jnt_dofadr, *dof_jntid, *dof_bodyid, *M_rowadr, *M_rownnz;
  double* dof_length;
  long long nbody, njnt, nsite, ngeom, nhfield, nv, ninertia;
};

// After a patch's values are written (mjcf_forge::split::PatchPlan::finish): mj_setConst
// on scratch data `d`; then the kinematics and centres of mass at qpos0, and the
// joint-space inertia (what the compiler's statistics read; mj_setConst of 3.17 and 4.0
// leaves those statistics as they were).
void mjf_patch_set_const(mjModel* m, mjData* d) { mj_setConst(m, d); }

void mjf_patch_kinematics(const mjModel* m, mjData* d) {
  mju_copy(d->qpos, m->qpos0, m->nq);
  mj_kinematics(m, d);
  mj_comPos(m, d);
}

void mjf_patch_make_m(const mjModel* m, mjData* d) { mj_makeM(m, d); }

// The name of the element of `kind` (as mjf_patch_name2id takes it) with id `id`; NULL when
// it has none.
const char* mjf_patch_id2name(const mjModel* m, const char* kind, int id) {
  if (strcmp(kind, "body") == 0) return mj_id2name(m, mjOBJ_BODY, id);
  return NULL;
}

// The arrays of `m` and of `d` (as mjf_patch_kinematics and mjf_patch_make_m left it) the statistics read.
void mjf_patch_stat_arrays(mjModel* m, const mjData* d, struct mjf_stat_arrays* out) {
  out->xpos = d->xpos;
  out->xipos = d->xipos;
  out->xanchor = d->xanchor;
  out->site_xpos = d->site_xpos;
  out->geom_xpos = d->geom_xpos;
  out->geom_rbound = m->geom_rbound;
  out->geom_size = m->geom_size;
  out->hfield_size = m->hfield_size;
  out->body_mass = m->body_mass;
  out->inertia = d->M;
  out->geom_type = m->geom_type;
  out->geom_dataid = m->geom_dataid;
  out->body_parentid = m->body_parentid;
  out->body_geomadr = m->body_geomadr;
  out->body_geomnum = m->body_geomnum;
  out->jnt_bodyid = m->jnt_bodyid;
  out->jnt_type = m->jnt_type;
  out->jnt_dofadr = m->jnt_dofadr;
  out->dof_jntid = m->dof_jntid;
  out->dof_bodyid = m->dof_bodyid;
  out->M_rowadr = m->M_rowadr;
  out->M_rownnz = m->M_rownnz;
  out->dof_length = m->dof_length;
  out->nbody = m->nbody;
  out->njnt = m->njnt;
  out->nsite = m->nsite;
  out->ngeom = m->ngeom;
  out->nhfield = m->nhfield;
  out->nv = m->nv;
  out->ninertia = m->nv ? (long long)m->M_rowadr[m->nv - 1] + m->M_rownnz[m->nv - 1] : 0;
}

// Sets the model's statistics, laid out as mjf_patch_get_stat gives them.
void mjf_patch_set_stat(mjModel* m, const double in[7]) {
  m->stat.meaninertia = in[0];
  m->stat.meanmass = in[1];
  m->stat.meansize = in[2];
  m->stat.extent = in[3];
  m->stat.center[0] = in[4];
  m->stat.center[1] = in[5];
  m->stat.center[2] = in[6];
}

// mjModel's arrays in MJMODEL_POINTERS order: each one's name and C type as MuJoCo
// declares it ("mjtNum", "float", "int", "mjtByte"...).
static const struct {
  const char* name;
  const char* type;
} kArrays[] = {
#define X(type, field, nr, nc) {#field, #type},
#define XNV X
    MJMODEL_POINTERS
#undef XNV
#undef X
};
static const int kNumArrays = (int)(sizeof(kArrays) / sizeof(kArrays[0]));

// The name of mjModel's array number `i`; NULL past the last.
const char* mjf_patch_array_name(int i) {
  return i >= 0 && i < kNumArrays ? kArrays[i].name : NULL;
}

// The C type of mjModel's array number `i`; NULL past the last.
const char* mjf_patch_array_type(int i) {
  return i >= 0 && i < kNumArrays ? kArrays[i].type : NULL;
}

// mjModel's sizes in MJMODEL_SIZES order: each one's name, and its value in a model
// (whatever integer type this MuJoCo gives sizes).
static const char* kSizes[] = {
#define X(name) #name,
    MJMODEL_SIZES
#undef X
};
static const int kNumSizes = (int)(sizeof(kSizes) / sizeof(kSizes[0]));

// The name of mjModel's size number `i`; NULL past the last.
const char* mjf_patch_size_name(int i) {
  return i >= 0 && i < kNumSizes ? kSizes[i] : NULL;
}

// The value of mjModel's size number `i` in `m`; -1 past the last.
long long mjf_patch_size(const mjModel* m, int i) {
  int k = 0;
#define X(name) if (k++ == i) return (long long)m->name;
  MJMODEL_SIZES
#undef X
  return -1;
}

// The names buffer of `m` (every name, NUL-separated) and its length in bytes.
const char* mjf_patch_names(const mjModel* m, long long* len) {
  *len = (long long)m->nnames;
  return m->names;
}

// MuJoCo's enum constant `name`, as a superset's tree-by-tree derivation asks for them
// (split/trees/); 0 with *found = 0 for any other name.
int mjf_tree_constant(const char* name, int* found) {
  static const struct {
    const char* name;
    int value;
  } table[] = {
      {"mjWRAP_JOINT", mjWRAP_JOINT},       {"mjWRAP_SITE", mjWRAP_SITE},
      {"mjWRAP_SPHERE", mjWRAP_SPHERE},     {"mjWRAP_CYLINDER", mjWRAP_CYLINDER},
      {"mjTRN_JOINT", mjTRN_JOINT},         {"mjTRN_JOINTINPARENT", mjTRN_JOINTINPARENT},
      {"mjTRN_SITE", mjTRN_SITE},           {"mjTRN_SLIDERCRANK", mjTRN_SLIDERCRANK},
      {"mjTRN_BODY", mjTRN_BODY},           {"mjTRN_TENDON", mjTRN_TENDON},
      {"mjEQ_JOINT", mjEQ_JOINT},           {"mjEQ_TENDON", mjEQ_TENDON},
      {"mjOBJ_BODY", mjOBJ_BODY},           {"mjOBJ_SITE", mjOBJ_SITE},
      {"mjSAMEFRAME_NONE", mjSAMEFRAME_NONE},
  };
  for (size_t i = 0; i < sizeof(table) / sizeof(table[0]); i++) {
    if (strcmp(name, table[i].name) == 0) {
      *found = 1;
      return table[i].value;
    }
  }
  *found = 0;
  return 0;
}

void mjf_tree_camlight(const mjModel* m, mjData* d) { mj_camlight(m, d); }

// The mjData array `name` of the frames a tree-by-tree derivation reads after the
// kinematics, and how many numbers it holds; NULL and 0 for any other name.
const mjtNum* mjf_tree_data(const mjModel* m, const mjData* d, const char* name,
                            size_t* count) {
  if (strcmp(name, "xpos") == 0) {
    *count = 3 * (size_t)m->nbody;
    return d->xpos;
  }
  if (strcmp(name, "subtree_com") == 0) {
    *count = 3 * (size_t)m->nbody;
    return d->subtree_com;
  }
  if (strcmp(name, "cam_xpos") == 0) {
    *count = 3 * (size_t)m->ncam;
    return d->cam_xpos;
  }
  if (strcmp(name, "cam_xmat") == 0) {
    *count = 9 * (size_t)m->ncam;
    return d->cam_xmat;
  }
  if (strcmp(name, "light_xpos") == 0) {
    *count = 3 * (size_t)m->nlight;
    return d->light_xpos;
  }
  if (strcmp(name, "light_xdir") == 0) {
    *count = 3 * (size_t)m->nlight;
    return d->light_xdir;
  }
  *count = 0;
  return NULL;
}
