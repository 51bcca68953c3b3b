// The MuJoCo side of patching a compiled model (src/compiled/cache.rs). Compiled by build.rs
// against the linked MuJoCo's own headers, as the FFI's shim is, so mjModel's and mjData's
// layouts are never copied into Rust: arrays are found by name through MuJoCo's X-macro
// table.
#include <math.h>
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

static double dist3(const double* a, const double* b) {
  double d0 = a[0] - b[0], d1 = a[1] - b[1], d2 = a[2] - b[2];
  return sqrt(d0 * d0 + d1 * d1 + d2 * d2);
}

static double maxd(double a, double b) { return a > b ? a : b; }

static void update_box(double* lo, double* hi, const double* p, double r) {
  for (int k = 0; k < 3; k++) {
    lo[k] = lo[k] < p[k] - r ? lo[k] : p[k] - r;
    hi[k] = hi[k] > p[k] + r ? hi[k] : p[k] + r;
  }
}

// The statistics and dof lengths the compiler derives from the model at qpos0, which
// mj_setConst of MuJoCo 3.17 and 4.0 leaves as they were: computed as the compiler does,
// the same operations in the same order. `d` is scratch (its state is overwritten).
static void statistics(mjModel* m, mjData* d) {
  mju_copy(d->qpos, m->qpos0, m->nq);
  mj_kinematics(m, d);
  mj_comPos(m, d);
  mj_makeM(m, d);
  double lo[3] = {1e10, 1e10, 1e10}, hi[3] = {-1e10, -1e10, -1e10};
  for (int i = 1; i < m->nbody; i++) {
    update_box(lo, hi, d->xpos + 3 * i, 0);
    update_box(lo, hi, d->xipos + 3 * i, 0);
  }
  for (int i = 0; i < m->njnt; i++) update_box(lo, hi, d->xanchor + 3 * i, 0);
  for (int i = 0; i < m->nsite; i++) update_box(lo, hi, d->site_xpos + 3 * i, 0);
  for (int i = 0; i < m->ngeom; i++) {
    double r = 0;
    if (m->geom_rbound[i] > 0) {
      r = m->geom_rbound[i];
    } else if (m->geom_type[i] == mjGEOM_PLANE) {
      const double* s = m->geom_size + 3 * i;
      r = (s[0] || s[1]) ? maxd(s[0], s[1]) * 0.1 : 0.01;
    } else if (m->geom_type[i] == mjGEOM_HFIELD) {
      const double* h = m->hfield_size + 4 * m->geom_dataid[i];
      r = maxd(h[0], maxd(h[1], maxd(h[2], h[3]))) * 0.1;
    }
    update_box(lo, hi, d->geom_xpos + 3 * i, r);
  }
  for (int k = 0; k < 3; k++) m->stat.center[k] = (lo[k] + hi[k]) * 0.5;
  if (hi[0] > lo[0]) {
    m->stat.extent = maxd(1e-5, maxd(hi[0] - lo[0], maxd(hi[1] - lo[1], hi[2] - lo[2])));
  }

  // Body sizes: the largest com-joint distance (the joint's body and its parent), then
  // geom bounds around the com.
  mj_markStack(d);
  double* body = mj_stackAllocNum(d, m->nbody);
  for (int i = 0; i < m->nbody; i++) body[i] = 0;
  for (int j = 0; j < m->njnt; j++) {
    int id = m->jnt_bodyid[j];
    body[id] = maxd(body[id], dist3(d->xipos + 3 * id, d->xanchor + 3 * j));
    id = m->body_parentid[id];
    body[id] = maxd(body[id], dist3(d->xipos + 3 * id, d->xanchor + 3 * j));
  }
  body[0] = 0;
  for (int i = 1; i < m->nbody; i++) {
    for (int g = m->body_geomadr[i]; g < m->body_geomadr[i] + m->body_geomnum[i]; g++) {
      if (m->geom_rbound[g] > 0) {
        body[i] = maxd(body[i], m->geom_rbound[g] + dist3(d->xipos + 3 * i, d->geom_xpos + 3 * g));
      }
    }
  }
  if (m->nbody > 1) {
    m->stat.meansize = 0;
    for (int i = 1; i < m->nbody; i++) {
      body[i] = maxd(body[i], 1e-5);
      m->stat.meansize += body[i] / (m->nbody - 1);
    }
  }
  // Rotational dofs take their body's size.
  for (int i = 0; i < m->nv; i++) {
    int jnt = m->dof_jntid[i];
    int type = m->jnt_type[jnt];
    int offset = i - m->jnt_dofadr[jnt];
    int rotational = type == mjJNT_BALL || type == mjJNT_HINGE || (type == mjJNT_FREE && offset >= 3);
    m->dof_length[i] = rotational ? body[m->dof_bodyid[i]] : 1;
  }
  mj_freeStack(d);
  m->stat.extent = maxd(m->stat.extent, 2 * m->stat.meansize);
  if (m->nbody > 1) {
    double mass = 0;
    for (int i = 1; i < m->nbody; i++) mass += m->body_mass[i];
    m->stat.meanmass = mass / (m->nbody - 1);
  }
  if (m->nv) {
    double inertia = 0;
    for (int i = 0; i < m->nv; i++) inertia += d->M[m->M_rowadr[i] + m->M_rownnz[i] - 1];
    m->stat.meaninertia = inertia / m->nv;
  }
}

// After a patch's values are written: mj_setConst on scratch data `d`, the compiler's
// statistics, then the statistics the scene's <statistic> fixes (bit k of `fixed` for
// value k of `values`, as mjf_patch_get_stat lays them out; center is bit 4).
void mjf_patch_finish(mjModel* m, mjData* d, int fixed, const double values[7]) {
  mj_setConst(m, d);
  statistics(m, d);
  if (fixed & 1) m->stat.meaninertia = values[0];
  if (fixed & 2) m->stat.meanmass = values[1];
  if (fixed & 4) m->stat.meansize = values[2];
  if (fixed & 8) m->stat.extent = values[3];
  if (fixed & 16) {
    m->stat.center[0] = values[4];
    m->stat.center[1] = values[5];
    m->stat.center[2] = values[6];
  }
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

// Superset: stat.meaninertia as the variant's own model has it, the mean of the mass
// matrix's diagonal (at qpos0, as the statistics left it in `d`) over the `n` dofs in
// `keep` (the variant's, in order).
void mjf_patch_meaninertia(mjModel* m, const mjData* d, const int* keep, int n) {
  if (n <= 0) return;
  double inertia = 0;
  for (int k = 0; k < n; k++) {
    int i = keep[k];
    inertia += d->M[m->M_rowadr[i] + m->M_rownnz[i] - 1];
  }
  m->stat.meaninertia = inertia / n;
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
