// The C side of the preview tier (src/preview/sys.rs declares these functions): a headless
// OpenGL context, and MuJoCo's own renderer (mjv_*, mjr_*) drawing one model into memory.
//
// Compiled by build.rs against the headers of the MuJoCo that the build links, like the
// FFI's shim. No GL or EGL header is needed: EGL and OSMesa are opened at run time with
// dlopen, so a build never links them and a machine without them fails with a message
// instead of at load time. MuJoCo finds the GL functions itself once a context is current
// (render/glad/glad.c: eglGetProcAddress or OSMesaGetProcAddress of the library already
// loaded into the process, found by dl_iterate_phdr), and only once per process.
#include <dlfcn.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <mujoco/mujoco.h>

// ---------------------------------------------------------------------------------------
// EGL, the constants and types we use (from the Khronos headers).

typedef void* EGLDisplay;
typedef void* EGLConfig;
typedef void* EGLContext;
typedef void* EGLSurface;
typedef void* EGLDeviceEXT;
typedef int EGLint;
typedef unsigned int EGLBoolean;
typedef unsigned int EGLenum;

#define EGL_ALPHA_SIZE 0x3021
#define EGL_BLUE_SIZE 0x3022
#define EGL_GREEN_SIZE 0x3023
#define EGL_RED_SIZE 0x3024
#define EGL_DEPTH_SIZE 0x3025
#define EGL_STENCIL_SIZE 0x3026
#define EGL_SURFACE_TYPE 0x3033
#define EGL_NONE 0x3038
#define EGL_RENDERABLE_TYPE 0x3040
#define EGL_HEIGHT 0x3056
#define EGL_WIDTH 0x3057
#define EGL_PBUFFER_BIT 0x0001
#define EGL_OPENGL_BIT 0x0008
#define EGL_OPENGL_API 0x30A2
#define EGL_PLATFORM_DEVICE_EXT 0x313F
#define EGL_PLATFORM_SURFACELESS_MESA 0x31DD

typedef void* (*PfnGetProcAddress)(const char*);
typedef EGLDisplay (*PfnGetDisplay)(void*);
typedef EGLDisplay (*PfnGetPlatformDisplay)(EGLenum, void*, const EGLint*);
typedef EGLBoolean (*PfnQueryDevices)(EGLint, EGLDeviceEXT*, EGLint*);
typedef EGLBoolean (*PfnInitialize)(EGLDisplay, EGLint*, EGLint*);
typedef EGLBoolean (*PfnTerminate)(EGLDisplay);
typedef EGLBoolean (*PfnChooseConfig)(EGLDisplay, const EGLint*, EGLConfig*, EGLint, EGLint*);
typedef EGLBoolean (*PfnBindApi)(EGLenum);
typedef EGLContext (*PfnCreateContext)(EGLDisplay, EGLConfig, EGLContext, const EGLint*);
typedef EGLBoolean (*PfnDestroyContext)(EGLDisplay, EGLContext);
typedef EGLSurface (*PfnCreatePbuffer)(EGLDisplay, EGLConfig, const EGLint*);
typedef EGLBoolean (*PfnDestroySurface)(EGLDisplay, EGLSurface);
typedef EGLBoolean (*PfnMakeCurrent)(EGLDisplay, EGLSurface, EGLSurface, EGLContext);

// OSMesa (from GL/osmesa.h).
#define OSMESA_RGBA 0x1908
#define GL_UNSIGNED_BYTE 0x1401
typedef void* (*PfnOsmesaCreate)(unsigned int, int, int, int, void*);
typedef void (*PfnOsmesaDestroy)(void*);
typedef unsigned char (*PfnOsmesaMakeCurrent)(void*, void*, unsigned int, int, int);

// ---------------------------------------------------------------------------------------
// The context.

enum { GL_EGL = 1, GL_OSMESA = 2 };

typedef struct mjfGl {
  int kind;
  void* lib;
  // EGL
  EGLDisplay display;
  EGLContext context;
  EGLSurface surface;
  PfnTerminate terminate;
  PfnDestroyContext destroy_context;
  PfnDestroySurface destroy_surface;
  PfnMakeCurrent make_current;
  // OSMesa
  void* osmesa;
  unsigned char* buffer;
  int width, height;
  PfnOsmesaDestroy osmesa_destroy;
  PfnOsmesaMakeCurrent osmesa_make_current;
} mjfGl;

static void say(char* err, int err_len, const char* what) {
  if (err && err_len > 0) {
    size_t used = strlen(err);
    if (used > 0 && used + 2 < (size_t)err_len) {
      strcat(err, "; ");
      used += 2;
    }
    if (used + 1 < (size_t)err_len) {
      strncat(err, what, (size_t)err_len - used - 1);
    }
  }
}

// An initialized display with a config for a desktop OpenGL context, or NULL.
static EGLDisplay egl_initialize(mjfGl* gl, EGLDisplay display, EGLConfig* config) {
  PfnInitialize initialize = (PfnInitialize)dlsym(gl->lib, "eglInitialize");
  PfnChooseConfig choose = (PfnChooseConfig)dlsym(gl->lib, "eglChooseConfig");
  if (!display || !initialize || !choose) return NULL;
  EGLint major = 0, minor = 0;
  if (!initialize(display, &major, &minor)) return NULL;
  // Surfaceless displays may offer no pbuffer configs: ask without the surface type next.
  const EGLint with_pbuffer[] = {
    EGL_RED_SIZE, 8, EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8, EGL_ALPHA_SIZE, 8,
    EGL_DEPTH_SIZE, 24, EGL_STENCIL_SIZE, 8, EGL_SURFACE_TYPE, EGL_PBUFFER_BIT,
    EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
  const EGLint without[] = {
    EGL_RED_SIZE, 8, EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8, EGL_ALPHA_SIZE, 8,
    EGL_DEPTH_SIZE, 24, EGL_STENCIL_SIZE, 8, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
  EGLint n = 0;
  if ((choose(display, with_pbuffer, config, 1, &n) && n > 0) ||
      (choose(display, without, config, 1, &n) && n > 0)) {
    return display;
  }
  gl->terminate(display);
  return NULL;
}

// Tries every EGL display we know, in order: a device (EGL_EXT_platform_device, what
// MuJoCo's Python `egl` backend uses), Mesa's surfaceless platform, the default display.
static int egl_open(mjfGl* gl, char* err, int err_len) {
  gl->lib = dlopen("libEGL.so.1", RTLD_NOW | RTLD_LOCAL);
  if (!gl->lib) gl->lib = dlopen("libEGL.so", RTLD_NOW | RTLD_LOCAL);
  if (!gl->lib) {
    say(err, err_len, "EGL: cannot open libEGL.so.1 (install libegl1 and a driver, e.g. "
        "Mesa's libegl-mesa0)");
    return 0;
  }
  PfnGetProcAddress get_proc = (PfnGetProcAddress)dlsym(gl->lib, "eglGetProcAddress");
  PfnGetDisplay get_display = (PfnGetDisplay)dlsym(gl->lib, "eglGetDisplay");
  PfnBindApi bind_api = (PfnBindApi)dlsym(gl->lib, "eglBindAPI");
  PfnCreateContext create_context = (PfnCreateContext)dlsym(gl->lib, "eglCreateContext");
  PfnCreatePbuffer create_pbuffer = (PfnCreatePbuffer)dlsym(gl->lib, "eglCreatePbufferSurface");
  gl->terminate = (PfnTerminate)dlsym(gl->lib, "eglTerminate");
  gl->destroy_context = (PfnDestroyContext)dlsym(gl->lib, "eglDestroyContext");
  gl->destroy_surface = (PfnDestroySurface)dlsym(gl->lib, "eglDestroySurface");
  gl->make_current = (PfnMakeCurrent)dlsym(gl->lib, "eglMakeCurrent");
  if (!get_proc || !get_display || !bind_api || !create_context || !create_pbuffer ||
      !gl->terminate || !gl->destroy_context || !gl->destroy_surface || !gl->make_current) {
    say(err, err_len, "EGL: libEGL.so.1 lacks EGL 1.4's functions");
    return 0;
  }
  PfnGetPlatformDisplay platform_display =
      (PfnGetPlatformDisplay)get_proc("eglGetPlatformDisplayEXT");
  PfnQueryDevices query_devices = (PfnQueryDevices)get_proc("eglQueryDevicesEXT");

  EGLConfig config = NULL;
  EGLDisplay display = NULL;
  if (platform_display && query_devices) {
    EGLDeviceEXT devices[16];
    EGLint count = 0;
    if (query_devices(16, devices, &count)) {
      for (EGLint i = 0; i < count && !display; i++) {
        display = egl_initialize(
            gl, platform_display(EGL_PLATFORM_DEVICE_EXT, devices[i], NULL), &config);
      }
    }
  }
  if (!display && platform_display) {
    display = egl_initialize(
        gl, platform_display(EGL_PLATFORM_SURFACELESS_MESA, NULL, NULL), &config);
  }
  if (!display) display = egl_initialize(gl, get_display(NULL), &config);
  if (!display) {
    say(err, err_len, "EGL: no display could be initialized with an OpenGL config "
        "(no device, surfaceless or default display)");
    return 0;
  }
  gl->display = display;
  if (!bind_api(EGL_OPENGL_API)) {
    say(err, err_len, "EGL: the display offers no desktop OpenGL (eglBindAPI)");
    return 0;
  }
  // No attributes: a compatibility context, which MuJoCo's fixed-function renderer needs.
  gl->context = create_context(display, config, NULL, NULL);
  if (!gl->context) {
    say(err, err_len, "EGL: cannot create an OpenGL context");
    return 0;
  }
  // MuJoCo draws into its own framebuffer object: no surface is needed where the display
  // allows that (EGL_KHR_surfaceless_context), else a 1x1 pbuffer.
  if (gl->make_current(display, NULL, NULL, gl->context)) return 1;
  const EGLint size[] = {EGL_WIDTH, 1, EGL_HEIGHT, 1, EGL_NONE};
  gl->surface = create_pbuffer(display, config, size);
  if (gl->surface && gl->make_current(display, gl->surface, gl->surface, gl->context)) {
    return 1;
  }
  say(err, err_len, "EGL: cannot make the OpenGL context current");
  return 0;
}

static int osmesa_open(mjfGl* gl, int width, int height, char* err, int err_len) {
  const char* names[] = {"libOSMesa.so.8", "libOSMesa.so.6", "libOSMesa.so"};
  for (size_t i = 0; i < sizeof(names) / sizeof(names[0]) && !gl->lib; i++) {
    gl->lib = dlopen(names[i], RTLD_NOW | RTLD_LOCAL);
  }
  if (!gl->lib) {
    say(err, err_len, "OSMesa: cannot open libOSMesa.so (install libosmesa6)");
    return 0;
  }
  PfnOsmesaCreate create = (PfnOsmesaCreate)dlsym(gl->lib, "OSMesaCreateContextExt");
  PfnOsmesaMakeCurrent make_current = (PfnOsmesaMakeCurrent)dlsym(gl->lib, "OSMesaMakeCurrent");
  gl->osmesa_make_current = make_current;
  gl->width = width;
  gl->height = height;
  gl->osmesa_destroy = (PfnOsmesaDestroy)dlsym(gl->lib, "OSMesaDestroyContext");
  if (!create || !make_current || !gl->osmesa_destroy) {
    say(err, err_len, "OSMesa: libOSMesa lacks OSMesaCreateContextExt");
    return 0;
  }
  gl->osmesa = create(OSMESA_RGBA, 24, 8, 0, NULL);
  if (!gl->osmesa) {
    say(err, err_len, "OSMesa: cannot create a context");
    return 0;
  }
  gl->buffer = (unsigned char*)malloc((size_t)width * (size_t)height * 4);
  if (!gl->buffer || !make_current(gl->osmesa, gl->buffer, GL_UNSIGNED_BYTE, width, height)) {
    say(err, err_len, "OSMesa: cannot make the context current");
    return 0;
  }
  return 1;
}

static void gl_close(mjfGl* gl) {
  if (gl->display && gl->make_current) {
    gl->make_current(gl->display, NULL, NULL, NULL);
    if (gl->surface) gl->destroy_surface(gl->display, gl->surface);
    if (gl->context) gl->destroy_context(gl->display, gl->context);
    // Not eglTerminate: a display is shared by the process (the same handle comes back to
    // every caller), and another context may still use it.
  }
  if (gl->osmesa) gl->osmesa_destroy(gl->osmesa);
  free(gl->buffer);
  // The library stays loaded: MuJoCo keeps the GL function pointers it found in it.
  memset(gl, 0, sizeof(*gl));
}

// A current OpenGL context on this thread: `backend` 0 tries EGL then OSMesa, 1 EGL only,
// 2 OSMesa only. NULL with the reasons in `err` when none could be made. `width` and
// `height` size OSMesa's buffer (MuJoCo renders into its own framebuffer object anyway).
mjfGl* mjf_gl_new(int backend, int width, int height, char* err, int err_len) {
  if (err && err_len > 0) err[0] = '\0';
  mjfGl* gl = (mjfGl*)calloc(1, sizeof(mjfGl));
  if (!gl) {
    say(err, err_len, "out of memory");
    return NULL;
  }
  if (backend != 2) {
    if (egl_open(gl, err, err_len)) {
      gl->kind = GL_EGL;
      return gl;
    }
    void* lib = gl->lib;
    gl_close(gl);
    // A failed libEGL must not stay loaded beside OSMesa: MuJoCo's loader would take the
    // first GL platform library it finds in the process.
    if (lib) dlclose(lib);
  }
  if (backend != 1) {
    if (osmesa_open(gl, width, height, err, err_len)) {
      gl->kind = GL_OSMESA;
      return gl;
    }
    void* lib = gl->lib;
    gl_close(gl);
    if (lib) dlclose(lib);
  }
  free(gl);
  return NULL;
}

// "egl" or "osmesa".
const char* mjf_gl_kind(const mjfGl* gl) { return gl->kind == GL_EGL ? "egl" : "osmesa"; }

// Makes `gl` current on this thread again (another context may have been made current
// since); 0 when that fails.
int mjf_gl_make_current(mjfGl* gl) {
  if (gl->kind == GL_EGL) {
    return gl->make_current(gl->display, gl->surface, gl->surface, gl->context) ? 1 : 0;
  }
  return gl->osmesa_make_current(gl->osmesa, gl->buffer, GL_UNSIGNED_BYTE, gl->width,
                                 gl->height) ? 1 : 0;
}

void mjf_gl_free(mjfGl* gl) {
  if (gl) {
    gl_close(gl);
    free(gl);
  }
}

// ---------------------------------------------------------------------------------------
// Rendering.

// What the contact sheet's rules (src/sheet/, in Rust) read of `m`, which this file then
// only carries out: mjv_defaultFreeCamera's six numbers (lookat x y z, distance, azimuth,
// elevation) into `cam`; `<visual><global fovy>` into `fovy`; per geom, at the initial
// pose (qpos0, mj_kinematics), its world position (3 each) into `xpos` and whether it
// collides (contype or conaffinity not 0) into `collides`; `xpos` NULL skips the pose.
// 0 on success, -1 when mjData cannot be made (`xpos` then left as it was).
int mjf_sheet_inputs(const mjModel* m, double cam[6], double* fovy, double* xpos,
                     int* collides) {
  mjvCamera c;
  mjv_defaultFreeCamera(m, &c);
  cam[0] = c.lookat[0];
  cam[1] = c.lookat[1];
  cam[2] = c.lookat[2];
  cam[3] = c.distance;
  cam[4] = c.azimuth;
  cam[5] = c.elevation;
  *fovy = m->vis.global.fovy;
  for (int g = 0; g < m->ngeom; g++) {
    collides[g] = m->geom_contype[g] != 0 || m->geom_conaffinity[g] != 0;
  }
  if (!xpos) return 0;
  mjData* d = mj_makeData(m);
  if (!d) return -1;
  mj_kinematics(m, d);
  memcpy(xpos, d->geom_xpos, sizeof(double) * 3 * (size_t)m->ngeom);
  mj_deleteData(d);
  return 0;
}

// Each geom's radius of its bounding sphere (ngeom of them) into `rbound`; MuJoCo's
// number of geom groups (mjNGROUP) returned.
int mjf_geom_rbound(const mjModel* m, double* rbound) {
  memcpy(rbound, m->geom_rbound, sizeof(double) * (size_t)m->ngeom);
  return mjNGROUP;
}

// Renders `m` at its initial pose (qpos0, mj_forward) into `rgb` (width x height x 3 bytes,
// bottom row first, as glReadPixels gives), from the free camera `free_cam`
// (the six numbers of src/sheet/'s FreeCamera) or from the model's camera `camid` when it
// is >= 0. The geoms drawn are the sheet's rule's (src/sheet/geoms.rs): `groups_set`, when not
// NULL, each geom's group for the render (ngeom of them); `groups_on`, when not NULL, which
// of the mjNGROUP geom groups are drawn (else MuJoCo's default option). Sites are not
// drawn. With `segment`, draws segmentation instead (flat colours, no multisampling)
// and writes into `seg` (width x height ints, bottom row first) the geom id of each pixel,
// -1 where no geom is. The model's visual settings and geom groups are restored before
// returning. 0 on success, else -1 with the reason in `err`.
int mjf_render(mjModel* m, int width, int height, const double free_cam[6], int camid,
               const int* groups_set, const int* groups_on, int segment, unsigned char* rgb,
               int* seg, char* err, int err_len) {
  if (err && err_len > 0) err[0] = '\0';
  int* groups = (int*)malloc(sizeof(int) * (size_t)(m->ngeom > 0 ? m->ngeom : 1));
  if (!groups) {
    say(err, err_len, "out of memory");
    return -1;
  }
  memcpy(groups, m->geom_group, sizeof(int) * (size_t)m->ngeom);
  int offwidth = m->vis.global.offwidth, offheight = m->vis.global.offheight;
  int offsamples = m->vis.quality.offsamples;
  if (m->vis.global.offwidth < width) m->vis.global.offwidth = width;
  if (m->vis.global.offheight < height) m->vis.global.offheight = height;
  if (segment) m->vis.quality.offsamples = 0;
  if (groups_set) memcpy(m->geom_group, groups_set, sizeof(int) * (size_t)m->ngeom);

  int result = -1;
  mjData* d = mj_makeData(m);
  mjvScene scn;
  mjv_defaultScene(&scn);
  mjrContext con;
  mjr_defaultContext(&con);
  if (!d) {
    say(err, err_len, "cannot allocate mjData");
    goto done;
  }
  mj_forward(m, d);

  mjvOption opt;
  mjv_defaultOption(&opt);
  for (int i = 0; i < mjNGROUP; i++) {
    opt.sitegroup[i] = 0;  // sites are markers, not the scene
    if (groups_on) opt.geomgroup[i] = groups_on[i] ? 1 : 0;
  }

  mjvCamera cam;
  mjv_defaultCamera(&cam);
  if (camid >= 0) {
    cam.type = mjCAMERA_FIXED;
    cam.fixedcamid = camid;
  } else {
    cam.type = mjCAMERA_FREE;
    cam.lookat[0] = free_cam[0];
    cam.lookat[1] = free_cam[1];
    cam.lookat[2] = free_cam[2];
    cam.distance = free_cam[3];
    cam.azimuth = free_cam[4];
    cam.elevation = free_cam[5];
  }

  mjv_makeScene(m, &scn, 10000);
  mjv_updateScene(m, d, &opt, NULL, &cam, mjCAT_ALL, &scn);
  if (segment) {
    scn.flags[mjRND_SEGMENT] = 1;
    scn.flags[mjRND_IDCOLOR] = 1;
  }
  mjr_makeContext(m, &con, mjFONTSCALE_150);
  if (!con.offFBO) {
    say(err, err_len, "MuJoCo could not make its offscreen framebuffer");
    goto done;
  }
  mjr_setBuffer(mjFB_OFFSCREEN, &con);
  mjrRect rect = {0, 0, width, height};
  mjr_render(rect, &scn, &con);
  mjr_readPixels(rgb, NULL, rect, &con);

  if (segment && seg) {
    // The colour of a pixel is its scene geom's segid + 1 (0: nothing drawn).
    int nseg = scn.ngeom + 1;
    int* geom_of = (int*)malloc(sizeof(int) * (size_t)nseg);
    if (!geom_of) {
      say(err, err_len, "out of memory");
      goto done;
    }
    for (int i = 0; i < nseg; i++) geom_of[i] = -1;
    for (int i = 0; i < scn.ngeom; i++) {
      const mjvGeom* g = scn.geoms + i;
      if (g->segid >= 0 && g->segid + 1 < nseg && g->objtype == mjOBJ_GEOM) {
        geom_of[g->segid + 1] = g->objid;
      }
    }
    for (long p = 0; p < (long)width * height; p++) {
      long id = rgb[3 * p] | (rgb[3 * p + 1] << 8) | ((long)rgb[3 * p + 2] << 16);
      seg[p] = (id >= 0 && id < nseg) ? geom_of[id] : -1;
    }
    free(geom_of);
  }
  result = 0;

done:
  mjr_freeContext(&con);
  mjv_freeScene(&scn);
  if (d) mj_deleteData(d);
  memcpy(m->geom_group, groups, sizeof(int) * (size_t)m->ngeom);
  free(groups);
  m->vis.global.offwidth = offwidth;
  m->vis.global.offheight = offheight;
  m->vis.quality.offsamples = offsamples;
  return result;
}
