/* The C ABI (footfall_c.h, libfootfall.so) used from C, as a plugin written in C uses it: the
 * header compiles as C11 (-Wall -Wextra -pedantic), and every call gives the answers and statuses
 * the header promises. Queries on a generated height field are checked against a brute-force
 * scan of its samples. Bad arguments (NULL pointers, count 0, unknown terrains, NaN, a zero step
 * direction) give their statuses and a reason without crashing; a footfalld client aimed at a
 * closed port answers FF_C_UNAVAILABLE.
 *
 * Usage: c_abi_test CHARACTER_FILE (data/characters/biped.json). Exits 1 naming every failed
 * check. */
#define _POSIX_C_SOURCE 200809L

#include <arpa/inet.h>
#include <math.h>
#include <netinet/in.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "footfall/client/footfall_c.h"

static int checks = 0;
static int failures = 0;

/* Counts a check; prints its name (and the details, printf style) when it fails. */
static int Check(int ok, const char* name, const char* format, ...) {
  ++checks;
  if (!ok) {
    va_list args;
    ++failures;
    fprintf(stderr, "c_abi_test: FAILED: %s", name);
    if (format && *format) {
      fputs(": ", stderr);
      va_start(args, format);
      vfprintf(stderr, format, args);
      va_end(args);
    }
    fputc('\n', stderr);
  }
  return ok;
}

/* Checks that a call returned `want` and, unless it is FF_C_OK, left a reason. */
static int CheckStatus(ffc_session* s, int32_t got, int32_t want, const char* name) {
  const char* error = ffc_last_error(s);
  if (!Check(got == want, name, "returned %d (%s), expected %d (%s); last error: %s", (int)got,
             ffc_status_name(got), (int)want, ffc_status_name(want), error ? error : "(NULL)"))
    return 0;
  if (want != FF_C_OK)
    return Check(error != NULL && error[0] != '\0', name, "ffc_last_error is empty");
  return 1;
}

/* The grid of samples: a height field y = f(x, z) over [0, 10] x [0, 10], 41 x 41 points. */
enum { kSide = 41, kSamples = kSide * kSide, kQueries = 120 };
static const double kSpacing = 0.25;
/* Stored samples are float offsets from the grid's centre: within about 6e-8 of their distance
 * to it (under 1e-6 here). */
static const double kEps = 1e-5;

static double Height(double x, double z) { return 0.4 * sin(0.9 * x) * cos(0.7 * z); }

static void MakeSamples(double* samples) {
  int i, j;
  for (i = 0; i < kSide; ++i) {
    for (j = 0; j < kSide; ++j) {
      double* v = samples + 6 * (i * kSide + j);
      const double x = i * kSpacing, z = j * kSpacing;
      /* The unit normal of the surface: (-dy/dx, 1, -dy/dz), normalised. */
      const double dx = 0.36 * cos(0.9 * x) * cos(0.7 * z);
      const double dz = -0.28 * sin(0.9 * x) * sin(0.7 * z);
      const double length = sqrt(dx * dx + 1 + dz * dz);
      v[0] = x, v[1] = Height(x, z), v[2] = z;
      v[3] = -dx / length, v[4] = 1 / length, v[5] = -dz / length;
    }
  }
}

/* A deterministic pseudo-random number in [lo, hi). */
static double Random(uint64_t* state, double lo, double hi) {
  *state = *state * UINT64_C(6364136223846793005) + UINT64_C(1442695040888963407);
  return lo + (hi - lo) * (double)(*state >> 12) / 4503599627370496.0;
}

static double Distance(const double* a, const double* b) {
  const double d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
  return sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
}

static int SameFoothold(const ffc_foothold* a, const ffc_foothold* b) {
  int k;
  if (a->status != b->status || a->index != b->index) return 0;
  for (k = 0; k < 3; ++k)
    if (a->point[k] != b->point[k] || a->normal[k] != b->normal[k]) return 0;
  return 1;
}

/* An answer that is a sample: its index, its point (as stored) and its unit normal. */
static int CheckSampleAnswer(const double* samples, const ffc_foothold* f, const char* name,
                             size_t query) {
  const double* v;
  if (!Check(f->index < (uint32_t)kSamples, name, "query %zu: index %u out of range", query,
             (unsigned)f->index))
    return 0;
  v = samples + 6 * f->index;
  if (!Check(Distance(f->point, v) <= kEps, name,
             "query %zu: point (%g, %g, %g) is not sample %u (%g, %g, %g)", query, f->point[0],
             f->point[1], f->point[2], (unsigned)f->index, v[0], v[1], v[2]))
    return 0;
  return Check(Distance(f->normal, v + 3) <= kEps, name,
               "query %zu: normal (%g, %g, %g) is not sample %u's (%g, %g, %g)", query,
               f->normal[0], f->normal[1], f->normal[2], (unsigned)f->index, v[3], v[4], v[5]);
}

/* ffc_snap and ffc_normal: the nearest sample, by brute force. */
static void CheckNearest(const double* samples, const double* points, const ffc_foothold* out,
                         size_t count, const char* name) {
  size_t q;
  int i;
  for (q = 0; q < count; ++q) {
    double best = INFINITY;
    for (i = 0; i < kSamples; ++i) {
      const double d = Distance(points + 3 * q, samples + 6 * i);
      if (d < best) best = d;
    }
    if (!Check(out[q].status == FF_C_OK, name, "query %zu: status %d", q, (int)out[q].status))
      continue;
    if (!CheckSampleAnswer(samples, &out[q], name, q)) continue;
    Check(fabs(Distance(points + 3 * q, out[q].point) - best) <= kEps, name,
          "query %zu: answer at distance %.9g, the nearest sample at %.9g", q,
          Distance(points + 3 * q, out[q].point), best);
  }
}

/* ffc_next: candidates lie ahead of the foot (dot(p - foot, direction) > 0) within the radius
 * (tolerance, or |direction| when tolerance <= 0) of foot + direction; the answer is the
 * candidate nearest that ideal point, or FF_C_NO_FOOTHOLD. Samples within kEps of a boundary may
 * go either way (the engine decides on stored values). Counts the answers of each kind. */
static void CheckNext(const double* samples, const double* steps, double tolerance,
                      const ffc_foothold* out, size_t count, const char* name, int* found,
                      int* none) {
  size_t q;
  int i, k;
  for (q = 0; q < count; ++q) {
    const double* foot = steps + 6 * q;
    const double* dir = foot + 3;
    const double length = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    const double radius = tolerance > 0 ? tolerance : length;
    double ideal[3], best = INFINITY;
    for (k = 0; k < 3; ++k) ideal[k] = foot[k] + dir[k];
    for (i = 0; i < kSamples; ++i) {
      const double* p = samples + 6 * i;
      const double ahead =
          (p[0] - foot[0]) * dir[0] + (p[1] - foot[1]) * dir[1] + (p[2] - foot[2]) * dir[2];
      const double d = Distance(p, ideal);
      if (ahead > kEps * length && d < radius - kEps && d < best) best = d;
    }
    if (out[q].status == FF_C_NO_FOOTHOLD) {
      ++*none;
      Check(best == INFINITY, name,
            "query %zu: no foothold, but a sample lies at %.9g of the ideal", q, best);
      continue;
    }
    if (!Check(out[q].status == FF_C_OK, name, "query %zu: status %d", q, (int)out[q].status))
      continue;
    ++*found;
    if (!CheckSampleAnswer(samples, &out[q], name, q)) continue;
    {
      const double* p = out[q].point;
      const double ahead =
          (p[0] - foot[0]) * dir[0] + (p[1] - foot[1]) * dir[1] + (p[2] - foot[2]) * dir[2];
      const double d = Distance(p, ideal);
      Check(ahead > -kEps * length && d <= radius + kEps, name,
            "query %zu: the answer is no candidate (ahead %g, distance %g, radius %g)", q, ahead, d,
            radius);
      Check(d <= best + kEps, name, "query %zu: answer at %.9g of the ideal, a candidate at %.9g",
            q, d, best);
    }
  }
}

/* The whole of a small text file, or NULL. */
static char* ReadFile(const char* path) {
  FILE* f = fopen(path, "rb");
  char* text = NULL;
  long size;
  if (!f) return NULL;
  if (fseek(f, 0, SEEK_END) == 0 && (size = ftell(f)) >= 0 && fseek(f, 0, SEEK_SET) == 0) {
    text = malloc((size_t)size + 1);
    if (text && fread(text, 1, (size_t)size, f) == (size_t)size) {
      text[size] = '\0';
    } else {
      free(text);
      text = NULL;
    }
  }
  fclose(f);
  return text;
}

/* A loopback TCP port that nothing listens on: one the system gave and took back. */
static int ClosedPort(void) {
  struct sockaddr_in address;
  socklen_t length = sizeof address;
  int port = 0;
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return 0;
  memset(&address, 0, sizeof address);
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  address.sin_port = 0;
  if (bind(fd, (struct sockaddr*)&address, sizeof address) == 0 &&
      getsockname(fd, (struct sockaddr*)&address, &length) == 0)
    port = ntohs(address.sin_port);
  close(fd);
  return port;
}

static void TestQueries(ffc_session* s, uint32_t terrain, const double* samples) {
  static double points[3 * kQueries], steps[6 * kQueries];
  static ffc_foothold batch[kQueries];
  ffc_foothold one;
  uint64_t random = 20261204;
  size_t q;
  int pass, found = 0, none = 0;

  for (q = 0; q < kQueries; ++q) {
    points[3 * q] = Random(&random, -1, 11);
    points[3 * q + 1] = Random(&random, -1, 2);
    points[3 * q + 2] = Random(&random, -1, 11);
  }
  /* 1. ffc_snap and ffc_normal, as one batch and one query at a time. */
  for (pass = 0; pass < 2; ++pass) {
    const char* name =
        pass ? "ffc_normal answers the nearest sample" : "ffc_snap answers the nearest sample";
    int32_t (*query)(ffc_session*, uint32_t, const double*, size_t, ffc_foothold*) =
        pass ? ffc_normal : ffc_snap;
    if (!CheckStatus(s, query(s, terrain, points, kQueries, batch), FF_C_OK, name)) continue;
    CheckNearest(samples, points, batch, kQueries, name);
    for (q = 0; q < kQueries; ++q) {
      memset(&one, 0, sizeof one);
      if (!CheckStatus(s, query(s, terrain, points + 3 * q, 1, &one), FF_C_OK, name)) break;
      Check(SameFoothold(&one, &batch[q]), name, "query %zu alone differs from the batch", q);
    }
  }

  /* 2. ffc_next: feet on samples stepping 0.7 in every heading, and feet anywhere. */
  for (q = 0; q < kQueries; ++q) {
    double* v = steps + 6 * q;
    const double heading = Random(&random, 0, 6.283185307179586);
    if (q % 2 == 0) {
      const int i = (int)Random(&random, 0, kSamples);
      memcpy(v, samples + 6 * i, 3 * sizeof(double));
    } else {
      v[0] = Random(&random, -2, 12), v[1] = Random(&random, -1, 1), v[2] = Random(&random, -2, 12);
    }
    v[3] = 0.7 * cos(heading), v[4] = Random(&random, -0.2, 0.1), v[5] = 0.7 * sin(heading);
  }
  for (pass = 0; pass < 2; ++pass) {
    const double tolerance = pass ? 0.3 : 0;
    const char* name = pass ? "ffc_next with a tolerance answers the nearest candidate"
                            : "ffc_next answers the nearest candidate";
    if (!CheckStatus(s, ffc_next(s, terrain, steps, kQueries, tolerance, batch), FF_C_OK, name))
      continue;
    CheckNext(samples, steps, tolerance, batch, kQueries, name, &found, &none);
    for (q = 0; q < kQueries; ++q) {
      memset(&one, 0, sizeof one);
      if (!CheckStatus(s, ffc_next(s, terrain, steps + 6 * q, 1, tolerance, &one), FF_C_OK, name))
        break;
      Check(SameFoothold(&one, &batch[q]), name, "query %zu alone differs from the batch", q);
    }
  }
  Check(found > kQueries / 2 && none > 0,
        "ffc_next finds footholds and reports none off the terrain",
        "%d found, %d without a foothold", found, none);
}

static void TestBadArguments(ffc_session* s, uint32_t terrain) {
  double points[6] = {5, 0, 5, 5, 0, 5};
  double steps[12] = {5, 0, 5, 0.7, 0, 0, 5, 0, 5, 0.7, 0, 0};
  double samples[12] = {0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 1, 0};
  ffc_foothold out[2];
  uint32_t handle = 0;
  const uint32_t unknown = terrain + 1000;
  uint64_t count = 0;
  double bounds[6];
  char* json = NULL;

  /* 3. NULL pointers. */
  CheckStatus(NULL, ffc_snap(NULL, terrain, points, 1, out), FF_C_INVALID_ARGUMENT,
              "ffc_snap on a NULL session");
  Check(ffc_last_error(NULL) != NULL && ffc_last_error(NULL)[0] != '\0',
        "ffc_last_error of a NULL session says so", "");
  CheckStatus(s, ffc_snap(s, terrain, NULL, 1, out), FF_C_INVALID_ARGUMENT,
              "ffc_snap with NULL points");
  CheckStatus(s, ffc_normal(s, terrain, points, 1, NULL), FF_C_INVALID_ARGUMENT,
              "ffc_normal with NULL out");
  CheckStatus(s, ffc_next(s, terrain, NULL, 1, 0, out), FF_C_INVALID_ARGUMENT,
              "ffc_next with NULL steps");
  CheckStatus(s, ffc_next(s, terrain, steps, 1, 0, NULL), FF_C_INVALID_ARGUMENT,
              "ffc_next with NULL out");
  CheckStatus(s, ffc_load_samples(s, NULL, 2, "x", &handle), FF_C_INVALID_ARGUMENT,
              "ffc_load_samples with NULL samples");
  CheckStatus(s, ffc_load_samples(s, samples, 2, "x", NULL), FF_C_INVALID_ARGUMENT,
              "ffc_load_samples with a NULL terrain");
  CheckStatus(s, ffc_load_file(s, NULL, 0, &handle), FF_C_INVALID_ARGUMENT,
              "ffc_load_file with a NULL path");
  CheckStatus(s, ffc_load_server_file(s, "x.pts", 0, NULL), FF_C_INVALID_ARGUMENT,
              "ffc_load_server_file with a NULL terrain");
  CheckStatus(s, ffc_generate(s, terrain, NULL, &json), FF_C_INVALID_ARGUMENT,
              "ffc_generate with a NULL request");
  CheckStatus(s, ffc_generate(s, terrain, "{}", NULL), FF_C_INVALID_ARGUMENT,
              "ffc_generate with a NULL walk_json");
  CheckStatus(s, ffc_check_character(s, NULL), FF_C_INVALID_ARGUMENT,
              "ffc_check_character with NULL text");

  /* 4. Count 0: queries have nothing to answer; a terrain needs a sample. */
  CheckStatus(s, ffc_snap(s, terrain, NULL, 0, NULL), FF_C_OK, "ffc_snap of 0 points");
  CheckStatus(s, ffc_next(s, terrain, NULL, 0, 0, NULL), FF_C_OK, "ffc_next of 0 steps");
  Check(
      ffc_load_samples(s, samples, 0, "empty", &handle) != FF_C_OK && ffc_last_error(s)[0] != '\0',
      "ffc_load_samples of 0 samples fails with a reason", "last error: %s", ffc_last_error(s));

  /* Counts no memory can hold (more bytes than an address space has): refused before anything
   * is read or allocated. */
  CheckStatus(s, ffc_snap(s, terrain, points, SIZE_MAX / 8, out), FF_C_LIMIT_EXCEEDED,
              "ffc_snap of more points than memory holds");
  CheckStatus(s, ffc_next(s, terrain, steps, SIZE_MAX / 8, 0, out), FF_C_LIMIT_EXCEEDED,
              "ffc_next of more steps than memory holds");
  CheckStatus(s, ffc_load_samples(s, samples, SIZE_MAX / 8, "huge", &handle), FF_C_LIMIT_EXCEEDED,
              "ffc_load_samples of more samples than memory holds");

  /* 5. An unknown terrain. */
  CheckStatus(s, ffc_snap(s, unknown, points, 1, out), FF_C_UNKNOWN_TERRAIN,
              "ffc_snap on an unknown terrain");
  CheckStatus(s, ffc_normal(s, unknown, points, 1, out), FF_C_UNKNOWN_TERRAIN,
              "ffc_normal on an unknown terrain");
  CheckStatus(s, ffc_next(s, unknown, steps, 1, 0, out), FF_C_UNKNOWN_TERRAIN,
              "ffc_next on an unknown terrain");
  CheckStatus(s, ffc_info(s, unknown, &count, bounds), FF_C_UNKNOWN_TERRAIN,
              "ffc_info on an unknown terrain");
  CheckStatus(s, ffc_unload(s, unknown), FF_C_UNKNOWN_TERRAIN, "ffc_unload of an unknown terrain");

  /* 6. NaN: a query answers for itself (the call succeeds, the item is invalid); a NaN
   * tolerance or sample fails the call. A zero or infinite step direction is invalid. */
  points[3] = NAN;
  if (CheckStatus(s, ffc_snap(s, terrain, points, 2, out), FF_C_OK, "ffc_snap of a NaN point")) {
    Check(out[0].status == FF_C_OK, "ffc_snap answers the finite point beside a NaN one",
          "status %d", (int)out[0].status);
    Check(out[1].status == FF_C_INVALID_ARGUMENT, "ffc_snap of a NaN point is invalid", "status %d",
          (int)out[1].status);
  }
  steps[9] = 0, steps[10] = 0, steps[11] = 0;
  if (CheckStatus(s, ffc_next(s, terrain, steps, 2, 0, out), FF_C_OK,
                  "ffc_next with a zero direction")) {
    Check(out[0].status == FF_C_OK, "ffc_next answers the step beside a zero direction",
          "status %d", (int)out[0].status);
    Check(out[1].status == FF_C_INVALID_ARGUMENT, "ffc_next with a zero direction is invalid",
          "status %d", (int)out[1].status);
  }
  steps[9] = NAN;
  steps[6] = INFINITY;
  if (CheckStatus(s, ffc_next(s, terrain, steps, 2, 0, out), FF_C_OK,
                  "ffc_next with a NaN direction"))
    Check(out[1].status == FF_C_INVALID_ARGUMENT, "ffc_next with a NaN direction is invalid",
          "status %d", (int)out[1].status);
  CheckStatus(s, ffc_next(s, terrain, steps, 1, NAN, out), FF_C_INVALID_ARGUMENT,
              "ffc_next with a NaN tolerance");
  CheckStatus(s, ffc_load_file(s, "/nonexistent.pts", -INFINITY, &handle), FF_C_INVALID_ARGUMENT,
              "ffc_load_file with a separation of -infinity");
  CheckStatus(s, ffc_load_server_file(s, "/nonexistent.pts", -INFINITY, &handle),
              FF_C_INVALID_ARGUMENT, "ffc_load_server_file with a separation of -infinity");
  CheckStatus(s, ffc_load_file(s, "/nonexistent.pts", NAN, &handle), FF_C_INVALID_ARGUMENT,
              "ffc_load_file with a NaN separation");
  CheckStatus(s, ffc_load_file(s, "/nonexistent.pts", -1, &handle), FF_C_IO_ERROR,
              "ffc_load_file with a separation of -1 (the default) reads the file");
  samples[7] = NAN;
  CheckStatus(s, ffc_load_samples(s, samples, 2, "nan", &handle), FF_C_INVALID_ARGUMENT,
              "ffc_load_samples of a NaN coordinate");
  Check(strstr(ffc_last_error(s), "sample 1") != NULL, "ffc_load_samples names the bad sample",
        "last error: %s", ffc_last_error(s));
  samples[7] = 0, samples[9] = 0, samples[10] = 0, samples[11] = 0;
  CheckStatus(s, ffc_load_samples(s, samples, 2, "zero", &handle), FF_C_INVALID_ARGUMENT,
              "ffc_load_samples of a zero normal");
}

/* Whether `text` is well-formed UTF-8 (RFC 3629) without control characters (C0, DEL, C1) or
 * line separators (U+2028, U+2029): one line a plugin can show and decode. */
static int OneLineOfUtf8(const char* text) {
  const unsigned char* p = (const unsigned char*)text;
  while (*p) {
    int n, i;
    unsigned code;
    if (*p < 0x80) {
      if (*p < 0x20 || *p == 0x7f) return 0;
      ++p;
      continue;
    }
    n = (*p & 0xe0) == 0xc0 ? 2 : (*p & 0xf0) == 0xe0 ? 3 : (*p & 0xf8) == 0xf0 ? 4 : 0;
    if (n == 0) return 0;
    code = *p & (0x7fu >> n);
    for (i = 1; i < n; ++i) {
      if ((p[i] & 0xc0) != 0x80) return 0;
      code = (code << 6) | (p[i] & 0x3fu);
    }
    if ((n == 2 && code < 0x80) || (n == 3 && code < 0x800) || (n == 4 && code < 0x10000) ||
        code > 0x10ffff || (code >= 0xd800 && code <= 0xdfff) || (code >= 0x80 && code <= 0x9f) ||
        code == 0x2028 || code == 0x2029)
      return 0;
    p += n;
  }
  return 1;
}

/* 6b. ffc_last_error is one line of UTF-8 of bounded length, whatever the caller passed: names,
 * paths and request text with line breaks, bytes that are not UTF-8, and megabytes. */
static void TestErrorText(ffc_session* s) {
  double samples[6] = {0, 0, 0, 0, 1, 0};
  uint32_t handle = 0;
  enum { kLong = 1 << 20 };
  char* name = malloc(kLong + 1);
  char* walk = (char*)&handle; /* not NULL: a failed ffc_generate sets it to NULL */
  const char* error;
  if (!Check(name != NULL, "memory for a long name", "")) return;
  CheckStatus(s,
              ffc_load_samples(s, samples, 0, "two\nlines\r\x85\xe2\x80\xa8 \xff\xc0\xaf", &handle),
              FF_C_INVALID_ARGUMENT, "ffc_load_samples of 0 samples under an odd name");
  error = ffc_last_error(s);
  Check(OneLineOfUtf8(error), "ffc_last_error shows an odd name as one line of UTF-8",
        "last error: %s", error);
  Check(strstr(error, "two?lines") != NULL, "ffc_last_error shows a line break as '?'",
        "last error: %s", error);
  CheckStatus(s, ffc_load_file(s, "/nonexistent\n\xff.pts", 0, &handle), FF_C_IO_ERROR,
              "ffc_load_file of a missing path with a line break");
  error = ffc_last_error(s);
  Check(OneLineOfUtf8(error), "ffc_last_error shows an odd path as one line of UTF-8",
        "last error: %s", error);
  CheckStatus(s, ffc_generate(s, 1, "{\"character\": \"\xff\"}", &walk), FF_C_PARSE_ERROR,
              "ffc_generate of a request that is not UTF-8");
  Check(walk == NULL, "a failed ffc_generate sets walk_json to NULL", "");
  Check(OneLineOfUtf8(ffc_last_error(s)), "ffc_last_error quotes a bad request as UTF-8",
        "last error: %s", ffc_last_error(s));
  walk = (char*)&handle;
  CheckStatus(s, ffc_generate(s, 1, NULL, &walk), FF_C_INVALID_ARGUMENT,
              "ffc_generate with a NULL request, again");
  Check(walk == NULL, "ffc_generate with a NULL request sets walk_json to NULL", "");
  walk = (char*)&handle;
  Check(ffc_generate(NULL, 1, "{}", &walk) == FF_C_INVALID_ARGUMENT && walk == NULL,
        "ffc_generate on a NULL session sets walk_json to NULL", "");

  memset(name, 'a', kLong);
  name[kLong] = '\0';
  memcpy(name, "/nonexistent/", 13);
  CheckStatus(s, ffc_load_samples(s, samples, 0, name, &handle), FF_C_INVALID_ARGUMENT,
              "ffc_load_samples of 0 samples under a name of 1 MiB");
  error = ffc_last_error(s);
  Check(strlen(error) <= 8192 && strstr(error, "bytes)") != NULL,
        "ffc_last_error cuts a reason of 1 MiB to 8192 bytes, saying how long it was",
        "%zu bytes: %.60s...%s", strlen(error), error,
        strlen(error) > 60 ? error + strlen(error) - 40 : "");
  CheckStatus(s, ffc_load_file(s, name, 0, &handle), FF_C_IO_ERROR,
              "ffc_load_file of a path of 1 MiB");
  Check(strlen(ffc_last_error(s)) <= 8192, "ffc_last_error cuts a path of 1 MiB", "%zu bytes",
        strlen(ffc_last_error(s)));
  /* A cut never splits a character. */
  {
    size_t i;
    for (i = 0; i + 2 <= kLong; i += 2) memcpy(name + i, "\xc3\xa9", 2);
    name[kLong - (kLong % 2)] = '\0';
    CheckStatus(s, ffc_load_samples(s, samples, 0, name, &handle), FF_C_INVALID_ARGUMENT,
                "ffc_load_samples of 0 samples under a long name of e-acute");
    Check(OneLineOfUtf8(ffc_last_error(s)), "ffc_last_error cuts on a whole character",
          "last error ends: %s", ffc_last_error(s) + strlen(ffc_last_error(s)) - 30);
  }
  free(name);
}

static void TestCharacterAndWalk(ffc_session* s, uint32_t terrain, const char* character_path) {
  char* character = ReadFile(character_path);
  char* request;
  char* json = NULL;
  int32_t status;
  size_t size;
  if (!Check(character != NULL, "the character file reads", "%s", character_path)) return;

  /* 7. ffc_check_character: a good character, and bad ones with their problem named. */
  CheckStatus(s, ffc_check_character(s, character), FF_C_OK, "ffc_check_character of biped.json");
  CheckStatus(s, ffc_check_character(s, "{\"format\": "), FF_C_PARSE_ERROR,
              "ffc_check_character of text that is not JSON");
  status = ffc_check_character(s, "{\"format\": \"footfall-character\", \"version\": 1}");
  Check(status != FF_C_OK && ffc_last_error(s)[0] != '\0',
        "ffc_check_character of a character without feet fails with a reason",
        "status %d, last error: %s", (int)status, ffc_last_error(s));

  /* 8. ffc_generate: a few steps along +X from the middle of the terrain. */
  size = strlen(character) + 200;
  request = malloc(size);
  if (!Check(request != NULL, "memory for the request", "")) {
    free(character);
    return;
  }
  snprintf(request, size,
           "{\"character\": %s, \"start\": [5, 0, 5], \"heading\": [1, 0, 0], \"steps\": 4}",
           character);
  if (CheckStatus(s, ffc_generate(s, terrain, request, &json), FF_C_OK, "ffc_generate") &&
      Check(json != NULL, "ffc_generate fills walk_json", "")) {
    Check(json[0] == '{', "the walk is a JSON object", "it starts with %.20s", json);
    Check(strstr(json, "\"tracks\"") != NULL, "the walk has tracks", "%.200s", json);
    Check(strstr(json, "\"footfall-walk\"") != NULL, "the walk's format is footfall-walk", "%.200s",
          json);
  }
  ffc_free_string(json);
  json = NULL;
  CheckStatus(s, ffc_generate(s, terrain + 1000, request, &json), FF_C_UNKNOWN_TERRAIN,
              "ffc_generate on an unknown terrain");
  CheckStatus(s, ffc_generate(s, terrain, "{\"character\": ", &json), FF_C_PARSE_ERROR,
              "ffc_generate of a request that is not JSON");
  snprintf(request, size, "{\"character\": %s, \"steps\": -1}", character);
  /* generate_request.h: a bad field is FF_C_PARSE_ERROR or FF_C_INVALID_ARGUMENT, named. */
  status = ffc_generate(s, terrain, request, &json);
  Check(status == FF_C_PARSE_ERROR || status == FF_C_INVALID_ARGUMENT,
        "ffc_generate of -1 steps is refused", "status %d", (int)status);
  Check(strstr(ffc_last_error(s), "'steps'") != NULL, "ffc_generate names the bad field",
        "last error: %s", ffc_last_error(s));
  /* 9. ffc_generate_with_notes: the walk ffc_generate gives, and its notes as lines. */
  snprintf(request, size,
           "{\"character\": %s, \"start\": [5, 0, 5], \"heading\": [1, 0, 0], \"steps\": 4}",
           character);
  {
    char* plain = NULL;
    char* notes = NULL;
    CheckStatus(s, ffc_generate(s, terrain, request, &plain), FF_C_OK, "ffc_generate again");
    if (CheckStatus(s, ffc_generate_with_notes(s, terrain, request, &json, &notes), FF_C_OK,
                    "ffc_generate_with_notes") &&
        Check(json != NULL && notes != NULL, "ffc_generate_with_notes fills both", "")) {
      Check(plain != NULL && strcmp(json, plain) == 0,
            "ffc_generate_with_notes gives ffc_generate's walk", "");
      Check(notes[0] == '\0', "a walk from the middle of the terrain has no notes", "notes: %s",
            notes);
    }
    ffc_free_string(plain);
    ffc_free_string(json);
    ffc_free_string(notes);
    json = NULL, notes = NULL;
    /* A start 20 m beyond the terrain's edge (the terrain spans 0 to 10 in x and z). */
    snprintf(request, size,
             "{\"character\": %s, \"start\": [-20, 0, 5], \"heading\": [1, 0, 0], "
             "\"steps\": 2}",
             character);
    if (CheckStatus(s, ffc_generate_with_notes(s, terrain, request, &json, &notes), FF_C_OK,
                    "ffc_generate_with_notes from a far start") &&
        Check(notes != NULL, "ffc_generate_with_notes fills notes", "")) {
      Check(strstr(notes, "the start (-20.0000, 0.0000, 5.0000)") != NULL &&
                notes[strlen(notes) - 1] == '\n',
            "a far start is one note line naming the start", "notes: %s", notes);
    }
    ffc_free_string(json);
    ffc_free_string(notes);
    json = NULL;
    notes = (char*)request; /* not NULL: a failed call sets it to NULL */
    CheckStatus(s, ffc_generate_with_notes(s, terrain + 1000, request, &json, &notes),
                FF_C_UNKNOWN_TERRAIN, "ffc_generate_with_notes on an unknown terrain");
    Check(notes == NULL && json == NULL, "a failed ffc_generate_with_notes sets both to NULL", "");
    CheckStatus(s, ffc_generate_with_notes(s, terrain, request, &json, NULL), FF_C_OK,
                "ffc_generate_with_notes without notes wanted");
    ffc_free_string(json);
    json = NULL;
  }
  free(request);
  free(character);
}

static double Seconds(void) {
  struct timespec now;
  clock_gettime(CLOCK_MONOTONIC, &now);
  return (double)now.tv_sec + 1e-9 * (double)now.tv_nsec;
}

static void Sleep(double seconds) {
  struct timespec wait;
  wait.tv_sec = (time_t)seconds;
  wait.tv_nsec = (long)((seconds - (double)wait.tv_sec) * 1e9);
  nanosleep(&wait, NULL);
}

/* A thread's call that waits out its timeout on a server that never answers. */
struct SlowCall {
  ffc_session* session;
  _Atomic int started;
  int32_t status;
};

static void* PingSlowly(void* arg) {
  struct SlowCall* call = arg;
  call->started = 1;
  call->status = ffc_ping(call->session);
  return NULL;
}

/* 9b. ffc_last_error answers at once while another thread's call on the session waits (for its
 * server, a load of minutes): it does not take its turn behind that call. The server is a
 * loopback socket that listens (connections complete in its backlog) but never answers. */
static void TestLastErrorDuringCall(void) {
  struct sockaddr_in address;
  socklen_t length = sizeof address;
  struct SlowCall call;
  pthread_t thread;
  double began, took;
  int port = 0;
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  if (!Check(fd >= 0, "a socket for a server that never answers", "")) return;
  memset(&address, 0, sizeof address);
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (bind(fd, (struct sockaddr*)&address, sizeof address) == 0 && listen(fd, 8) == 0 &&
      getsockname(fd, (struct sockaddr*)&address, &length) == 0)
    port = ntohs(address.sin_port);
  if (!Check(port > 0, "a loopback port that never answers",
             "bind, listen or getsockname failed")) {
    close(fd);
    return;
  }
  call.session = ffc_open_rpc("127.0.0.1", port, 2);
  call.started = 0;
  call.status = FF_C_OK;
  if (!Check(call.session != NULL, "ffc_open_rpc to a server that never answers", "") ||
      !Check(pthread_create(&thread, NULL, PingSlowly, &call) == 0, "a thread that pings", "")) {
    ffc_close(call.session);
    close(fd);
    return;
  }
  while (!call.started) Sleep(0.001);
  Sleep(0.3); /* the ping now waits for its answer */
  began = Seconds();
  Check(ffc_last_error(call.session) != NULL, "ffc_last_error during another thread's call", "");
  took = Seconds() - began;
  Check(took < 0.5, "ffc_last_error answers at once during another thread's call", "it took %.2f s",
        took);
  pthread_join(thread, NULL);
  CheckStatus(call.session, call.status, FF_C_UNAVAILABLE,
              "ffc_ping to a server that never answers");
  ffc_close(call.session);
  close(fd);
}

static void TestRpc(const char* character_path) {
  const double samples[6] = {0, 0, 0, 0, 1, 0};
  uint32_t terrain = 0;
  char port_text[16];
  const int port = ClosedPort();
  ffc_session* s;
  char* character;

  /* 9. ffc_open_rpc: NULL only on bad arguments. */
  Check(ffc_open_rpc(NULL, 0, 1) == NULL, "ffc_open_rpc refuses port 0", "");
  Check(ffc_open_rpc(NULL, 65536, 1) == NULL, "ffc_open_rpc refuses port 65536", "");
  Check(ffc_open_rpc(NULL, -1, 1) == NULL, "ffc_open_rpc refuses port -1", "");
  Check(ffc_open_rpc(NULL, 7407, NAN) == NULL, "ffc_open_rpc refuses a NaN timeout", "");
  Check(ffc_open_rpc(NULL, 7407, INFINITY) == NULL, "ffc_open_rpc refuses an infinite timeout", "");
  Check(ffc_open_rpc(NULL, 7407, -INFINITY) == NULL, "ffc_open_rpc refuses a -infinite timeout",
        "");
  Check(ffc_open_rpc(NULL, 7407, 2e6) == NULL, "ffc_open_rpc refuses a timeout above 1e6 s", "");
  Check(ffc_open_rpc(NULL, 7407, 1e-9) == NULL, "ffc_open_rpc refuses a timeout below 0.001 s", "");
  Check(ffc_open_rpc(NULL, 7407, 0.0009) == NULL, "ffc_open_rpc refuses a timeout of 0.9 ms", "");
  s = ffc_open_rpc(NULL, 7407, 0.001);
  Check(s != NULL, "ffc_open_rpc takes a timeout of 0.001 s", "");
  ffc_close(s);
  s = ffc_open_rpc(NULL, 7407, 0);
  Check(s != NULL, "ffc_open_rpc takes a NULL host and a timeout of 0", "");
  ffc_close(s);
  /* A port in the host, or stray brackets: "127.0.0.1:7407" was looked up as a host name. */
  Check(ffc_open_rpc("127.0.0.1:7407", 7407, 1) == NULL, "ffc_open_rpc refuses a host with a port",
        "");
  Check(ffc_open_rpc("[::1", 7407, 1) == NULL, "ffc_open_rpc refuses an unclosed bracket", "");
  Check(ffc_open_rpc("a:b", 7407, 1) == NULL, "ffc_open_rpc refuses colons in a name", "");
  /* Brackets around anything but an IPv6 address ("[]" opened a session with an empty host). */
  Check(ffc_open_rpc("[]", 7407, 1) == NULL, "ffc_open_rpc refuses empty brackets", "");
  Check(ffc_open_rpc("[localhost]", 7407, 1) == NULL, "ffc_open_rpc refuses a bracketed name", "");
  /* Each refusal says which argument was wrong (it was "no session" alone). */
  {
    const struct {
      const char* host;
      int port;
      double timeout_s;
      const char* said;
    } refused[] = {{NULL, 0, 1, "the port is outside 1-65535"},
                   {NULL, 7407, NAN, "the timeout is NaN, infinite or above 1e6 s"},
                   {NULL, 7407, 1e-9, "the timeout is below 0.001 s"},
                   {"127.0.0.1:7407", 7407, 1, "the host is no host name or IP address"}};
    for (size_t i = 0; i < sizeof refused / sizeof refused[0]; ++i) {
      Check(ffc_open_rpc(refused[i].host, refused[i].port, refused[i].timeout_s) == NULL,
            "ffc_open_rpc refuses it", "%s", refused[i].said);
      Check(strncmp(ffc_last_error(NULL), "no session (ffc_open_rpc: ", 26) == 0 &&
                strstr(ffc_last_error(NULL), refused[i].said) != NULL,
            "ffc_last_error(NULL) says why ffc_open_rpc refused", "expected '%s', got '%s'",
            refused[i].said, ffc_last_error(NULL));
    }
  }
  s = ffc_open_rpc("[::1]", 7407, 1);
  Check(s != NULL, "ffc_open_rpc takes an IPv6 address in brackets", "");
  ffc_close(s);

  if (!Check(port > 0, "a closed loopback port", "socket, bind or getsockname failed")) return;
  snprintf(port_text, sizeof port_text, "%d", port);
  s = ffc_open_rpc("127.0.0.1", port, 2);
  if (!Check(s != NULL, "ffc_open_rpc to a closed port opens a session (it connects lazily)", ""))
    return;
  Check(ffc_last_error(s) != NULL, "ffc_last_error of a new session is not NULL", "");
  CheckStatus(s, ffc_ping(s), FF_C_UNAVAILABLE, "ffc_ping to a closed port");
  Check(strstr(ffc_last_error(s), port_text) != NULL, "the reason names the server",
        "last error: %s", ffc_last_error(s));
  CheckStatus(s, ffc_load_samples(s, samples, 1, "one", &terrain), FF_C_UNAVAILABLE,
              "ffc_load_samples to a closed port");
  {
    /* An IPv6 address in brackets, as footfalld's --listen takes it: "[[::1]]:PORT" before. */
    char expected[64];
    ffc_session* v6 = ffc_open_rpc("[::1]", port, 2);
    snprintf(expected, sizeof expected, "[::1]:%d", port);
    if (Check(v6 != NULL, "ffc_open_rpc takes a bracketed IPv6 address", "")) {
      CheckStatus(v6, ffc_ping(v6), FF_C_UNAVAILABLE, "ffc_ping to [::1] at a closed port");
      Check(strstr(ffc_last_error(v6), expected) != NULL && !strstr(ffc_last_error(v6), "[["),
            "the reason names [::1]:PORT", "last error: %s", ffc_last_error(v6));
    }
    ffc_close(v6);
  }
  CheckStatus(s, ffc_load_server_file(s, "terrain/hills.pts", 0, &terrain), FF_C_UNAVAILABLE,
              "ffc_load_server_file to a closed port");
  CheckStatus(s, ffc_ping(s), FF_C_UNAVAILABLE, "ffc_ping to a closed port, again");
  /* No server call. */
  character = ReadFile(character_path);
  if (character)
    CheckStatus(s, ffc_check_character(s, character), FF_C_OK,
                "ffc_check_character on a session without a server");
  free(character);
  ffc_close(s);
}

int main(int argc, char** argv) {
  static double samples[6 * kSamples];
  ffc_session* s;
  uint32_t terrain = 0, other = 0;
  uint64_t count = 0;
  double bounds[6], lo[3] = {INFINITY, INFINITY, INFINITY},
                    hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  int i, k;

  if (argc != 2) {
    fprintf(stderr, "usage: c_abi_test CHARACTER_FILE\n");
    return 2;
  }
  Check(ffc_abi_version() == FFC_ABI_VERSION, "ffc_abi_version equals FFC_ABI_VERSION",
        "library %d, header %d", ffc_abi_version(), FFC_ABI_VERSION);
  Check(strcmp(ffc_status_name(FF_C_NO_FOOTHOLD), "no_foothold") == 0,
        "ffc_status_name names FF_C_NO_FOOTHOLD", "%s", ffc_status_name(FF_C_NO_FOOTHOLD));
  for (i = FF_C_OK; i <= FF_C_INTERNAL_ERROR; ++i)
    Check(ffc_status_name(i) != NULL && ffc_status_name(i)[0] != '\0',
          "ffc_status_name names every status", "status %d", i);
  Check(ffc_status_name(42) != NULL && strcmp(ffc_status_name(42), "unknown_status") == 0,
        "ffc_status_name of an unknown status", "%s", ffc_status_name(42));
  Check(ffc_status_name(-1) != NULL, "ffc_status_name of -1 is not NULL", "");
  ffc_close(NULL); /* ignored */

  s = ffc_open_embedded();
  if (!Check(s != NULL, "ffc_open_embedded opens a session", "")) return 1;
  CheckStatus(s, ffc_ping(s), FF_C_OK, "ffc_ping of the embedded engine");

  /* The terrain: count and bounds as loaded. */
  MakeSamples(samples);
  for (i = 0; i < kSamples; ++i)
    for (k = 0; k < 3; ++k) {
      if (samples[6 * i + k] < lo[k]) lo[k] = samples[6 * i + k];
      if (samples[6 * i + k] > hi[k]) hi[k] = samples[6 * i + k];
    }
  if (!CheckStatus(s, ffc_load_samples(s, samples, kSamples, "hills", &terrain), FF_C_OK,
                   "ffc_load_samples of a height field")) {
    ffc_close(s);
    return 1;
  }
  if (CheckStatus(s, ffc_info(s, terrain, &count, bounds), FF_C_OK, "ffc_info")) {
    Check(count == kSamples, "ffc_info counts the samples", "%llu", (unsigned long long)count);
    for (k = 0; k < 3; ++k)
      Check(fabs(bounds[k] - lo[k]) <= kEps && fabs(bounds[3 + k] - hi[k]) <= kEps,
            "ffc_info gives the bounds", "axis %d: [%g, %g], expected [%g, %g]", k, bounds[k],
            bounds[3 + k], lo[k], hi[k]);
  }

  CheckStatus(s, ffc_info(s, terrain, NULL, NULL), FF_C_OK,
              "ffc_info with NULL samples and bounds");
  {
    uint32_t unnamed = 0;
    if (CheckStatus(s, ffc_load_samples(s, samples, 1, NULL, &unnamed), FF_C_OK,
                    "ffc_load_samples with a NULL name"))
      CheckStatus(s, ffc_unload(s, unnamed), FF_C_OK, "ffc_unload of the unnamed terrain");
  }
  TestQueries(s, terrain, samples);
  TestBadArguments(s, terrain);
  TestErrorText(s);
  TestCharacterAndWalk(s, terrain, argv[1]);

  /* 10. Unloading: the handle is gone; another terrain is unaffected. */
  CheckStatus(s, ffc_load_samples(s, samples, 10, "ten", &other), FF_C_OK,
              "ffc_load_samples of a second terrain");
  Check(other != terrain, "terrains have distinct handles", "both %u", (unsigned)terrain);
  CheckStatus(s, ffc_unload(s, terrain), FF_C_OK, "ffc_unload");
  CheckStatus(s, ffc_unload(s, terrain), FF_C_UNKNOWN_TERRAIN, "ffc_unload twice");
  CheckStatus(s, ffc_info(s, terrain, &count, bounds), FF_C_UNKNOWN_TERRAIN,
              "ffc_info after ffc_unload");
  if (CheckStatus(s, ffc_info(s, other, &count, bounds), FF_C_OK, "ffc_info of the second terrain"))
    Check(count == 10, "the second terrain counts its samples", "%llu", (unsigned long long)count);
  ffc_close(s);

  TestRpc(argv[1]);
  TestLastErrorDuringCall();

  if (failures) {
    fprintf(stderr, "c_abi_test: %d of %d checks failed\n", failures, checks);
    return 1;
  }
  printf("c_abi_test: all %d checks passed\n", checks);
  return 0;
}
