// The MuJoCo side of the FFI (src/mujoco/sys.rs declares these functions).
//
// Compiled by build.rs against the headers of the MuJoCo that the build links, whichever
// version from 3.17.0 on, so the layouts of mjModel, mjData and mjVFS and MuJoCo's constants
// come from those headers, never from a Rust copy of them. Fields are looked up by name
// through MuJoCo's own X-macro tables (mjxmacro.h: MJMODEL_SIZES, MJMODEL_POINTERS), which
// MuJoCo keeps in step with mjModel; Rust names the fields it reads and checks the element
// size it expects.
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <mujoco/mujoco.h>

int mjf_header_version(void) { return mjVERSION_HEADER; }

int mjf_ngain(void) { return mjNGAIN; }

int mjf_nbias(void) { return mjNBIAS; }

// A deep copy into a new model (mj_copyModel allocates it), or NULL.
mjModel* mjf_copy_model(const mjModel* m) { return mj_copyModel(NULL, m); }

// The model in MuJoCo's binary format (mj_saveModel): with a NULL buffer its size in bytes;
// else written into `buffer` of `size` bytes (the size first asked).
long long mjf_save_model(const mjModel* m, void* buffer, long long size) {
  if (!buffer) return (long long)mj_sizeModel(m);
  mj_saveModel(m, NULL, buffer, (mjtSize)size);
  return size;
}

// mjModel.signature, which MuJoCo's binary format does not hold, read and written.
unsigned long long mjf_signature(const mjModel* m) { return m->signature; }
void mjf_set_signature(mjModel* m, unsigned long long s) { m->signature = s; }

// A model in MuJoCo's binary format read back (mj_loadModelBuffer), or NULL.
mjModel* mjf_load_model(const void* buffer, long long size) {
  return mj_loadModelBuffer(buffer, (mjtSize)size);
}

// mj_loadXML without making the parsed model MuJoCo's last loaded XML model (the one
// mj_saveLastXML writes, process-wide): the same parse, compile and messages as MuJoCo's
// own (xml_api.cc: the parser's error, else the compiler's, else the warnings joined by
// newlines, else an empty message), and the spec freed instead of kept.
static void mjf_copy_message(char* error, int error_sz, const char* message) {
  if (error && error_sz > 0) {
    strncpy(error, message ? message : "", error_sz);
    error[error_sz - 1] = 0;
  }
}

mjModel* mjf_load_xml(const char* filename, const mjVFS* vfs, char* error, int error_sz) {
  mjSpec* spec = mj_parseXML(filename, vfs, error, error_sz);
  if (!spec) {
    return NULL;
  }
  mjModel* m = mj_compile(spec, vfs);
  if (!m) {
    mjf_copy_message(error, error_sz, mjs_getError(spec));
    mj_deleteSpec(spec);
    return NULL;
  }
  int warnings = mjs_numWarnings(spec);
  if (error && error_sz > 0) {
    error[0] = 0;
    size_t used = 0;
    for (int i = 0; i < warnings && used + 1 < (size_t)error_sz; i++) {
      const char* w = mjs_getWarning(spec, i);
      int n = snprintf(error + used, error_sz - used, "%s%s", i ? "\n" : "", w ? w : "");
      if (n < 0) {
        break;
      }
      used += (size_t)n;
    }
  }
  mj_deleteSpec(spec);
  return m;
}

// A size field of mjModel (MJMODEL_SIZES); -1 when `name` is not one.
long long mjf_model_size(const mjModel* m, const char* name) {
#define X(field) if (strcmp(name, #field) == 0) return (long long)m->field;
  MJMODEL_SIZES
#undef X
  return -1;
}

// An array of mjModel (MJMODEL_POINTERS) and the size of its elements in bytes; NULL and
// 0 when `name` is not one.
const void* mjf_model_array(const mjModel* m, const char* name, size_t* elem_size) {
#define X(type, field, nr, nc)                      \
  if (strcmp(name, #field) == 0) {                  \
    *elem_size = sizeof(type);                      \
    return (const void*)m->field;                   \
  }
#define XNV X
  MJMODEL_POINTERS
#undef XNV
#undef X
  *elem_size = 0;
  return NULL;
}

// A fresh VFS on the heap (mjVFS's size is the headers' business), or NULL.
mjVFS* mjf_vfs_new(void) {
  mjVFS* vfs = (mjVFS*)malloc(sizeof(mjVFS));
  if (vfs) mj_defaultVFS(vfs);
  return vfs;
}

void mjf_vfs_free(mjVFS* vfs) {
  if (vfs) {
    mj_deleteVFS(vfs);
    free(vfs);
  }
}

// mjtObj of an object kind named as in MJCF ("body", ..., "key"); -1 for others.
int mjf_obj_type(const char* kind) {
  static const struct { const char* name; int obj; } kinds[] = {
    {"body", mjOBJ_BODY},         {"joint", mjOBJ_JOINT},       {"geom", mjOBJ_GEOM},
    {"site", mjOBJ_SITE},         {"camera", mjOBJ_CAMERA},     {"light", mjOBJ_LIGHT},
    {"mesh", mjOBJ_MESH},         {"material", mjOBJ_MATERIAL}, {"texture", mjOBJ_TEXTURE},
    {"tendon", mjOBJ_TENDON},     {"actuator", mjOBJ_ACTUATOR}, {"sensor", mjOBJ_SENSOR},
    {"equality", mjOBJ_EQUALITY}, {"key", mjOBJ_KEY},
  };
  for (size_t i = 0; i < sizeof(kinds) / sizeof(kinds[0]); i++) {
    if (strcmp(kinds[i].name, kind) == 0) return kinds[i].obj;
  }
  return -1;
}

// The contacts at qpos0 (mj_forward on fresh data): writes up to `max` of them into
// geom1/geom2/dist and returns how many there are (-1 when mjData cannot be made).
int mjf_initial_contacts(const mjModel* m, int max, int* geom1, int* geom2, double* dist) {
  mjData* d = mj_makeData(m);
  if (!d) return -1;
  mj_forward(m, d);
  int n = d->ncon;
  for (int i = 0; i < n && i < max; i++) {
    geom1[i] = d->contact[i].geom[0];
    geom2[i] = d->contact[i].geom[1];
    dist[i] = d->contact[i].dist;
  }
  mj_deleteData(d);
  return n;
}
