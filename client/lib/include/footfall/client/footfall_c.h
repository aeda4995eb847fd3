/* footfall_c.h: the C ABI of the footfall client library, for plugins (ctypes, Maya, Blender).
 *
 * A session is the embedded engine or a footfalld connection. Every function returns an
 * ff_c_status (0 = FF_C_OK, same values as ff_status in rpc/footfall.x); on failure,
 * ffc_last_error() gives a one-line reason. No function throws, aborts or raises a signal
 * (SIGPIPE is ignored once a session is opened). Calls on one session from several threads
 * take turns; open a session per thread to query in parallel. Counts no memory can hold give
 * FF_C_LIMIT_EXCEEDED. Points are world space, 3 doubles each; normals are unit.
 * A NULL session gives FF_C_INVALID_ARGUMENT (ffc_last_error(NULL) says "no session"); so does a
 * NULL pointer the call needs (an out pointer, a path, an array of count > 0) unless its
 * comment says NULL is allowed. Terrain handles belong to their session; one unloaded is
 * FF_C_UNKNOWN_TERRAIN after, as is one never given.
 * While a call on an RPC session waits for footfalld, the calling thread has every signal
 * blocked (libtirpc's clnt_vc_call does so for the whole call, up to its timeout): a host that
 * must take signals at once makes its footfalld calls from a thread of their own.
 */
#ifndef FOOTFALL_C_H_
#define FOOTFALL_C_H_

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define FFC_ABI_VERSION 1

typedef enum {
  FF_C_OK = 0,
  FF_C_NO_FOOTHOLD = 1,
  FF_C_INVALID_ARGUMENT = 2,
  FF_C_UNKNOWN_TERRAIN = 3,
  FF_C_LIMIT_EXCEEDED = 4,
  FF_C_IO_ERROR = 5,
  FF_C_PARSE_ERROR = 6,
  FF_C_ACCESS_DENIED = 7,
  FF_C_UNAVAILABLE = 8,
  FF_C_INTERNAL_ERROR = 9
} ff_c_status;

typedef struct ffc_session ffc_session;

/* One query answer; point/normal/index are valid when status == FF_C_OK. */
typedef struct {
  int32_t status;
  uint32_t index;
  double point[3];
  double normal[3];
} ffc_foothold;

/* FFC_ABI_VERSION of the loaded library. It changes only when an existing function's signature
 * or promise changes; functions added later keep it (a caller finds them by name). */
int ffc_abi_version(void);

/* Opens the in-process engine. NULL only when memory runs out (ffc_last_error(NULL) then says
 * so, on this thread). */
ffc_session* ffc_open_embedded(void);
/* Opens a footfalld client; it connects lazily (the first call may return FF_C_UNAVAILABLE).
 * host NULL means 127.0.0.1; timeout_s <= 0 means 10 s per call. A host name is looked up
 * within that timeout (a lookup that does not answer fails the call FF_C_UNAVAILABLE); a
 * literal IPv4 or IPv6 address needs no lookup; an IPv6 address may be in brackets ("[::1]").
 * NULL only on bad arguments: a host holding a port ("127.0.0.1:7407"), stray brackets or
 * brackets around anything but an IPv6 address ("[]"), a
 * port outside 1-65535, a timeout above 1e6 s, infinite or NaN, or one above 0 but below
 * 0.001 s (as footfall's --timeout: no call could be answered in it); or when memory runs out.
 * ffc_last_error(NULL) then says which, on this thread ("no session (ffc_open_rpc: the port is
 * outside 1-65535)"). */
ffc_session* ffc_open_rpc(const char* host, int port, double timeout_s);
/* Frees the session and its terrains (an RPC session unloads them from footfalld, connecting
 * again if a call failed or footfalld closed the connection, the connection and each unload
 * waiting at most 2 s): the pointer is invalid afterwards (closing it
 * twice, or while another thread is in a call on it, is undefined). NULL is ignored. */
void ffc_close(ffc_session* session);
/* The reason for the session's last failed call (from any thread), as a copy that stays valid
 * until this thread calls ffc_last_error again. Not cleared by calls that succeed. Never NULL.
 * It answers at once, also while another thread's call on the session is under way (it does not
 * take its turn behind a load of minutes).
 * One line of UTF-8 of at most 8192 bytes: names, paths and request text quoted in it show line
 * breaks, other control characters and bytes that are not UTF-8 as '?', and a longer reason is
 * cut on a whole character, ending "... (N bytes)". */
const char* ffc_last_error(const ffc_session* session);
/* Whether the session's engine answers: FF_C_OK, or FF_C_UNAVAILABLE (ffc_last_error says why)
 * when no footfalld answers within the call timeout. An RPC session calls the RPC NULL
 * procedure, which footfalld answers however busy it is with loads; it loads nothing. */
int32_t ffc_ping(ffc_session* s);
/* A stable name for a status, e.g. "no_foothold"; "unknown_status" for other values. Never NULL. */
const char* ffc_status_name(int32_t status);

/* Loads a terrain file read on this machine (points, meshes, height maps); separation > 0
 * resamples meshes, <= 0 takes the default; NaN or infinite is FF_C_INVALID_ARGUMENT. */
int32_t ffc_load_file(ffc_session* s, const char* path, double separation, uint32_t* terrain);
/* Loads a file under the server's data root (RPC), or a local path (embedded). */
int32_t ffc_load_server_file(ffc_session* s, const char* path, double separation,
                             uint32_t* terrain);
/* Loads `count` samples given as 6 doubles each: x y z nx ny nz. name labels the terrain in
 * messages and info (NULL: "samples"; footfalld keeps at most its first 256 bytes, cut on a whole
 * character). */
int32_t ffc_load_samples(ffc_session* s, const double* samples, size_t count, const char* name,
                         uint32_t* terrain);
/* Forgets the terrain; an RPC session asks footfalld to unload it, connecting again if a call
 * failed (best effort: FF_C_OK also when footfalld does not answer). */
int32_t ffc_unload(ffc_session* s, uint32_t terrain);
/* Sample count and world bounds (min xyz, max xyz) of a terrain; samples and bounds may each be
 * NULL. */
int32_t ffc_info(ffc_session* s, uint32_t terrain, uint64_t* samples, double bounds[6]);

/* Batch queries: points are 3 doubles each; steps are 6 doubles each (foot xyz, direction xyz).
 * out[i] answers item i. tolerance <= 0: the candidate radius is the step length.
 * A call that returns FF_C_OK answers every item: out[i].status is FF_C_OK, FF_C_NO_FOOTHOLD,
 * or FF_C_INVALID_ARGUMENT for a non-finite point, foot or direction, a zero direction, a
 * point, foot or ideal point (foot + direction) with a coordinate farther than 1e15 from the
 * terrain's centre, or (tolerance <= 0) a direction whose squared length overflows a double
 * (ffc_last_error is not set for an item). A NaN or infinite tolerance fails the whole call
 * with FF_C_INVALID_ARGUMENT. count 0 is allowed, with NULL arrays. */
int32_t ffc_snap(ffc_session* s, uint32_t terrain, const double* points, size_t count,
                 ffc_foothold* out);
int32_t ffc_normal(ffc_session* s, uint32_t terrain, const double* points, size_t count,
                   ffc_foothold* out);
int32_t ffc_next(ffc_session* s, uint32_t terrain, const double* steps, size_t count,
                 double tolerance, ffc_foothold* out);

/* Generates a walk with the step generator, exactly as `footfall generate` does.
 * request_json: {"character": {...character file object...} or "character_file": PATH,
 *                "start": [x,y,z], "heading": [x,y,z], "path": [[x,y,z],...], "steps": N,
 *                "start_frame": F, "up": [x,y,z], "fps": F, "crowd": N, "crowd_spacing": D,
 *                "foot_rotations": true|false, "scale": S, "unit": UNIT}
 * (keys as the command's flags; steps 0 to 1e6, crowd 1 to 1e6, crowd_spacing 0 for the
 * default; foot_rotations: each foot key of the walk JSON also has its "rotation"; scale as
 * --scale, the character's lengths multiplied; unit as --unit, the walk's linear unit; nesting
 * deeper than 32 levels is refused; the character file must be a regular file).
 * On FF_C_OK and on a walk that stopped early, *walk_json receives the walk as footfall's JSON
 * (release it with ffc_free_string); a walk that stopped early returns FF_C_NO_FOOTHOLD,
 * still fills *walk_json with the keys so far, and sets ffc_last_error() to why it stopped.
 * Every other return sets *walk_json to NULL (when walk_json is not NULL). */
int32_t ffc_generate(ffc_session* s, uint32_t terrain, const char* request_json, char** walk_json);
/* ffc_generate, which it equals in every return and in *walk_json, and the walk's notes: what
 * `footfall generate` prints as "note:" lines and the walk JSON does not carry (a start farther
 * than a step from the terrain and where the character starts instead, a step_length beyond
 * the reach and the step taken instead, a path walk whose steps ended short of its goal).
 * Whenever *walk_json receives a walk (FF_C_OK, or FF_C_NO_FOOTHOLD for a walk that stopped
 * early), *notes receives them as UTF-8 text: one line per note, each ending in '\n', in the
 * order `footfall generate` prints them, each line as ffc_last_error's (line breaks and other
 * control characters shown as '?', at most 8192 bytes, a longer note cut on a whole
 * character); "" when there are none. Release it with ffc_free_string. Every other return sets
 * *notes to NULL. notes may be NULL (no notes wanted). Added in ABI version 1 without changing
 * it: a caller finds it by name (dlsym, ctypes), and an older library lacks it. */
int32_t ffc_generate_with_notes(ffc_session* s, uint32_t terrain, const char* request_json,
                                char** walk_json, char** notes);
void ffc_free_string(char* text);

/* Why the session's last walk (ffc_generate or ffc_generate_with_notes) stopped early: FF_C_OK
 * when it did not stop (or none was generated yet), FF_C_NO_FOOTHOLD when it stopped at the
 * terrain, FF_C_UNAVAILABLE when footfalld failed mid-walk (both return FF_C_NO_FOOTHOLD with
 * the keys so far: this tells a dead server from a cliff). Added in ABI version 1 without
 * changing it: a caller finds it by name, and an older library lacks it. */
int32_t ffc_walk_stop(ffc_session* s);

/* Checks a character file's JSON object (text) as ffc_generate would read it, without
 * generating anything: FF_C_OK, or the status and ffc_last_error naming the first problem
 * (a plugin checks a file before it builds a rig from it). No server call. */
int32_t ffc_check_character(ffc_session* s, const char* character_json);

#ifdef __cplusplus
}
#endif

#endif /* FOOTFALL_C_H_ */
