/* The C ABI while memory runs out: run with libfootfall_failing_new preloaded (C++ allocations
 * fail, every FOOTFALL_FAIL_NEW_EVERY-th, while the file named by FOOTFALL_FAIL_NEW_WHILE
 * exists, after the number of allocations the file holds). Each round turns the failures on
 * around a walk, a character check and a query, the first failing 5 allocations later than in
 * the round before: every call must return (an error code with a
 * reason, or its answer), never abort the host. Sessions that cannot be opened say why through
 * ffc_last_error(NULL). Arguments: FLAG_FILE CHARACTER_FILE */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "footfall/client/footfall_c.h"

static const char* g_flag;

/* Failures on after the next `first` allocations, or off (first < 0). */
static void Fail(int first) {
  if (first >= 0) {
    FILE* f = fopen(g_flag, "w");
    if (f) {
      fprintf(f, "%d\n", first);
      fclose(f);
    }
  } else {
    unlink(g_flag);
  }
}

static int g_failures = 0;

static void Check(int ok, const char* what) {
  if (!ok) {
    fprintf(stderr, "FAIL: %s\n", what);
    ++g_failures;
  }
}

int main(int argc, char** argv) {
  if (argc != 3) return 2;
  g_flag = argv[1];
  static char character[65536];
  FILE* file = fopen(argv[2], "rb");
  if (!file) return 2;
  const size_t size = fread(character, 1, sizeof character - 1, file);
  fclose(file);
  character[size] = '\0';
  char request[4096];
  snprintf(request, sizeof request, "{\"character_file\": \"%s\", \"steps\": 3}", argv[2]);
  double samples[6 * 400];
  for (int i = 0; i < 400; ++i) {
    double* s = samples + 6 * i;
    s[0] = (i % 20) * 0.1, s[1] = 0, s[2] = (i / 20) * 0.1, s[3] = 0, s[4] = 1, s[5] = 0;
  }

  /* Opening with its first allocation failing: NULL, and the reason on this thread. */
  Fail(0);
  ffc_session* none = ffc_open_embedded();
  Fail(-1);
  Check(none == NULL, "ffc_open_embedded is NULL when its first allocation fails");
  Check(strstr(ffc_last_error(NULL), "ran out of memory") != NULL,
        "ffc_last_error(NULL) says the open ran out of memory");
  ffc_close(none);
  /* A later open refused for its arguments is no want of memory (the reason stayed). */
  Check(ffc_open_rpc("127.0.0.1", 0, 1.0) == NULL, "ffc_open_rpc refuses port 0");
  Check(strstr(ffc_last_error(NULL), "out of memory") == NULL &&
            strstr(ffc_last_error(NULL), "the port is outside 1-65535") != NULL,
        "ffc_last_error(NULL) after a refused open is no longer out of memory");

  /* A count no memory holds while memory has run out: refused with its reason (making the
   * reason's text threw out of the call, and the host aborted). */
  {
    ffc_session* s = ffc_open_embedded();
    uint32_t terrain = 0;
    Check(s != NULL && ffc_load_samples(s, samples, 400, "flat", &terrain) == FF_C_OK,
          "a session and a terrain with memory");
    ffc_foothold answer;
    const double point[3] = {1, 0.5, 1};
    Fail(0);
    const int32_t huge = ffc_snap(s, terrain, point, SIZE_MAX, &answer);
    const int32_t huge_next = ffc_next(s, terrain, point, SIZE_MAX, 0, &answer);
    const char* why = ffc_last_error(s);
    Fail(-1);
    Check(huge == FF_C_LIMIT_EXCEEDED && huge_next == FF_C_LIMIT_EXCEEDED,
          "a count beyond memory is FF_C_LIMIT_EXCEEDED while memory has run out");
    /* (Every allocation failing, the call may run out before it sizes its arrays.) */
    Check(strstr(why, "too many items for memory") != NULL || strstr(why, "out of memory") != NULL,
          "and says why");
    ffc_close(s);
  }

  int answered = 0, refused = 0;
  for (int round = 0; round < 120; ++round) {
    ffc_session* s = ffc_open_embedded();
    if (!s) {
      Check(0, "ffc_open_embedded with memory back");
      break;
    }
    uint32_t terrain = 0;
    Check(ffc_load_samples(s, samples, 400, "flat", &terrain) == FF_C_OK, "load with memory");
    /* (Allocations count only while failures are on: with a period above 1, each round's
     * calls start at another phase of it.) */
    char* walk = NULL;
    char* notes = NULL;
    Fail(round * 5); /* the first failure moves through the calls, round by round */
    const int32_t generated = ffc_generate_with_notes(s, terrain, request, &walk, &notes);
    const int32_t checked = ffc_check_character(s, character);
    ffc_foothold answer;
    const double point[3] = {1, 0.5, 1};
    const int32_t snapped = ffc_snap(s, terrain, point, 1, &answer);
    Fail(-1);
    if (generated == FF_C_OK) {
      ++answered;
      Check(walk != NULL && notes != NULL, "a walk returned OK has its text");
    } else {
      ++refused;
      Check(walk == NULL, "no walk on an error");
      Check(strlen(ffc_last_error(s)) > 0, "an error with a reason");
    }
    Check(checked == FF_C_OK || strlen(ffc_last_error(s)) > 0, "ffc_check_character answers");
    Check(snapped == FF_C_OK || strlen(ffc_last_error(s)) > 0, "ffc_snap answers");
    ffc_free_string(walk);
    ffc_free_string(notes);
    ffc_close(s);
  }
  printf("generate: %d walks, %d refusals (out of memory)\n", answered, refused);
  Check(refused > 0, "memory ran out in some generate calls");
  return g_failures ? 1 : 0;
}
