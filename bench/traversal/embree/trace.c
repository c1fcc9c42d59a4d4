/* Embree's side of the traversal benchmark (bench/traversal): reads triangles and rays
 * written by `yat-traversal`, builds one Embree 3 scene, traces every ray set with
 * rtcIntersect1 (closest hit) and rtcOccluded1 (any hit) on one thread, and writes the
 * thread CPU seconds and each ray's result.
 *
 * usage: embree-trace QUALITY GEOMETRY RAYS OUT
 *   QUALITY  low | medium | high (RTC_BUILD_QUALITY_*; high adds spatial splits)
 *   GEOMETRY u32 vertex count, f32 xyz per vertex, u32 triangle count, u32 x3 per triangle
 *   RAYS     u32 ray count, f32 x8 per ray (origin, direction, tnear, tfar)
 *   OUT      f64 closest seconds, f64 any seconds, then per ray: u32 prim (or ~0), f32 t,
 *            u8 occluded
 * Little-endian, as the machine writes it. Errors exit with status 1 and a message.
 */
#include <embree3/rtcore.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static void fail(const char *what) {
  fprintf(stderr, "embree-trace: %s\n", what);
  exit(1);
}

static void *read_all(const char *path, size_t *len) {
  FILE *f = fopen(path, "rb");
  if (!f) fail("cannot open input");
  fseek(f, 0, SEEK_END);
  long n = ftell(f);
  fseek(f, 0, SEEK_SET);
  if (n < 4) fail("input too short");
  void *buf = malloc((size_t)n);
  if (!buf || fread(buf, 1, (size_t)n, f) != (size_t)n) fail("cannot read input");
  fclose(f);
  *len = (size_t)n;
  return buf;
}

static double thread_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int main(int argc, char **argv) {
  if (argc != 5) fail("usage: embree-trace low|medium|high GEOMETRY RAYS OUT");
  enum RTCBuildQuality quality;
  if (!strcmp(argv[1], "low")) quality = RTC_BUILD_QUALITY_LOW;
  else if (!strcmp(argv[1], "medium")) quality = RTC_BUILD_QUALITY_MEDIUM;
  else if (!strcmp(argv[1], "high")) quality = RTC_BUILD_QUALITY_HIGH;
  else fail("quality must be low, medium or high");

  size_t glen, rlen;
  uint8_t *g = read_all(argv[2], &glen);
  uint32_t nv, nt;
  memcpy(&nv, g, 4);
  if (glen < 8 + (size_t)nv * 12) fail("geometry file truncated");
  memcpy(&nt, g + 4 + (size_t)nv * 12, 4);
  if (glen != 8 + (size_t)nv * 12 + (size_t)nt * 12) fail("geometry file size mismatch");
  const float *verts = (const float *)(g + 4);
  const uint32_t *tris = (const uint32_t *)(g + 8 + (size_t)nv * 12);
  for (size_t i = 0; i < (size_t)nt * 3; i++)
    if (tris[i] >= nv) fail("vertex index out of range");

  uint8_t *r = read_all(argv[3], &rlen);
  uint32_t nr;
  memcpy(&nr, r, 4);
  if (rlen != 4 + (size_t)nr * 32) fail("ray file size mismatch");
  const float *rays = (const float *)(r + 4);

  RTCDevice device = rtcNewDevice(NULL);
  if (!device) fail("rtcNewDevice failed");
  RTCScene scene = rtcNewScene(device);
  rtcSetSceneBuildQuality(scene, quality);
  RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  rtcSetGeometryBuildQuality(geom, quality);
  float *vb = rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                      3 * sizeof(float), nv);
  memcpy(vb, verts, (size_t)nv * 12);
  uint32_t *ib = rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                         3 * sizeof(uint32_t), nt);
  memcpy(ib, tris, (size_t)nt * 12);
  rtcCommitGeometry(geom);
  rtcAttachGeometry(scene, geom);
  rtcReleaseGeometry(geom);
  rtcCommitScene(scene);

  uint32_t *prim = malloc((size_t)nr * 4);
  float *t = malloc((size_t)nr * 4);
  uint8_t *occ = malloc(nr);
  if (!prim || !t || !occ) fail("out of memory");

  struct RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  double start = thread_seconds();
  for (uint32_t i = 0; i < nr; i++) {
    const float *q = rays + (size_t)i * 8;
    struct RTCRayHit rh;
    rh.ray.org_x = q[0]; rh.ray.org_y = q[1]; rh.ray.org_z = q[2];
    rh.ray.dir_x = q[3]; rh.ray.dir_y = q[4]; rh.ray.dir_z = q[5];
    rh.ray.tnear = q[6]; rh.ray.tfar = q[7];
    rh.ray.mask = 0xffffffffu; rh.ray.flags = 0; rh.ray.time = 0.0f; rh.ray.id = i;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &ctx, &rh);
    prim[i] = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? 0xffffffffu : rh.hit.primID;
    t[i] = rh.ray.tfar;
  }
  double closest = thread_seconds() - start;
  start = thread_seconds();
  for (uint32_t i = 0; i < nr; i++) {
    const float *q = rays + (size_t)i * 8;
    struct RTCRay ray;
    ray.org_x = q[0]; ray.org_y = q[1]; ray.org_z = q[2];
    ray.dir_x = q[3]; ray.dir_y = q[4]; ray.dir_z = q[5];
    ray.tnear = q[6]; ray.tfar = q[7];
    ray.mask = 0xffffffffu; ray.flags = 0; ray.time = 0.0f; ray.id = i;
    rtcOccluded1(scene, &ctx, &ray);
    occ[i] = ray.tfar == -INFINITY;
  }
  double any = thread_seconds() - start;

  FILE *out = fopen(argv[4], "wb");
  if (!out) fail("cannot write output");
  fwrite(&closest, 8, 1, out);
  fwrite(&any, 8, 1, out);
  for (uint32_t i = 0; i < nr; i++) {
    fwrite(prim + i, 4, 1, out);
    fwrite(t + i, 4, 1, out);
    fwrite(occ + i, 1, 1, out);
  }
  if (fclose(out) != 0) fail("cannot write output");
  rtcReleaseScene(scene);
  rtcReleaseDevice(device);
  return 0;
}
