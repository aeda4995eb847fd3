/* A plain C client of footfalld on rpcgen's stubs alone, as a client written from footfall.x
 * without the footfall client library would be: it calls every procedure of version 1 over
 * TCP, with AUTH_NONE and AUTH_SYS credentials, and checks what such a client meets: version 2
 * refused with the versions served, an unknown procedure refused, UDP not served (refused at
 * once, no timeout), and a full batch with a send size of FF_MAX_REQUEST_BYTES.
 *
 * Usage: plain_c_client PORT. Prints one line per check; exit 0 when all pass. */
#include <arpa/inet.h>
#include <netinet/in.h>
#include <rpc/rpc.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "footfall.h"

/* xdr_void as clnt_call takes it (through a function type any other converts to). */
#define XDR_VOID ((xdrproc_t)(void (*)(void))xdr_void)

static int failures = 0;

static void check(int ok, const char* what) {
  printf("%s: %s\n", ok ? "ok" : "FAILED", what);
  if (!ok) ++failures;
}

static struct sockaddr_in address(int port) {
  struct sockaddr_in a;
  memset(&a, 0, sizeof a);
  a.sin_family = AF_INET;
  a.sin_port = htons((unsigned short)port);
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  return a;
}

static CLIENT* tcp_client(int port, unsigned long version, unsigned size) {
  struct sockaddr_in a = address(port);
  int sock = RPC_ANYSOCK;
  CLIENT* c = clnttcp_create(&a, FOOTFALL_PROG, version, &sock, size, size);
  if (c) {
    struct timeval timeout = {10, 0};
    clnt_control(c, CLSET_TIMEOUT, (char*)&timeout);
  }
  return c;
}

/* Every procedure on `c`; `tag` names the credentials in the output. */
static void every_procedure(CLIENT* c, const char* tag) {
  char what[160];
#define CHECK(ok, text)                               \
  do {                                                \
    snprintf(what, sizeof what, "%s: %s", tag, text); \
    check(ok, what);                                  \
  } while (0)
  CHECK(ff_null_1(NULL, NULL, c) == RPC_SUCCESS, "FF_NULL");

  ff_upload_begin_args begin = {(char*)"plain-c", 400};
  ff_upload_reply upload;
  memset(&upload, 0, sizeof upload);
  CHECK(ff_upload_begin_1(&begin, &upload, c) == RPC_SUCCESS && upload.status == FF_OK,
        "FF_UPLOAD_BEGIN");
  ff_sample samples[400];
  for (int i = 0; i < 400; ++i) {
    ff_sample s = {{i % 20, 0, i / 20}, {0, 2, 0}};
    samples[i] = s;
  }
  ff_upload_chunk_args chunk = {upload.upload, {400, samples}};
  ff_status_reply status;
  memset(&status, 0, sizeof status);
  CHECK(ff_upload_chunk_1(&chunk, &status, c) == RPC_SUCCESS && status.status == FF_OK,
        "FF_UPLOAD_CHUNK");
  xdr_free((xdrproc_t)xdr_ff_status_reply, (char*)&status);
  ff_upload_args finish = {upload.upload};
  xdr_free((xdrproc_t)xdr_ff_upload_reply, (char*)&upload);
  ff_load_reply load;
  memset(&load, 0, sizeof load);
  CHECK(ff_upload_finish_1(&finish, &load, c) == RPC_SUCCESS && load.status == FF_OK,
        "FF_UPLOAD_FINISH");
  ff_terrain_args terrain = {load.terrain};
  xdr_free((xdrproc_t)xdr_ff_load_reply, (char*)&load);

  ff_info_reply info;
  memset(&info, 0, sizeof info);
  CHECK(ff_info_1(&terrain, &info, c) == RPC_SUCCESS && info.status == FF_OK &&
            info.samples == 400 && strcmp(info.name, "plain-c") == 0,
        "FF_INFO");
  xdr_free((xdrproc_t)xdr_ff_info_reply, (char*)&info);
  ff_list_reply list;
  memset(&list, 0, sizeof list);
  CHECK(ff_list_1(NULL, &list, c) == RPC_SUCCESS && list.status == FF_OK &&
            list.terrains.terrains_len >= 1,
        "FF_LIST");
  xdr_free((xdrproc_t)xdr_ff_list_reply, (char*)&list);

  ff_point_args point = {terrain.terrain, {3.2, 1, 4.1}};
  ff_result r;
  memset(&r, 0, sizeof r);
  CHECK(ff_snap_1(&point, &r, c) == RPC_SUCCESS && r.status == FF_OK && r.point.x == 3 &&
            r.point.z == 4,
        "FF_SNAP");
  CHECK(ff_normal_1(&point, &r, c) == RPC_SUCCESS && r.status == FF_OK && r.normal.y == 1,
        "FF_NORMAL (a unit normal)");
  ff_next_args next = {terrain.terrain, 0, {{3, 0, 3}, {1, 0, 0}}};
  CHECK(ff_next_1(&next, &r, c) == RPC_SUCCESS && r.status == FF_OK && r.point.x == 4, "FF_NEXT");

  memset(&status, 0, sizeof status);
  CHECK(ff_ask_again_1(NULL, &status, c) == RPC_SUCCESS && status.status == FF_OK, "FF_ASK_AGAIN");
  xdr_free((xdrproc_t)xdr_ff_status_reply, (char*)&status);
  ff_recent_args after = {0};
  ff_recent_reply recent;
  memset(&recent, 0, sizeof recent);
  CHECK(ff_recent_1(&after, &recent, c) == RPC_SUCCESS && recent.status == FF_OK &&
            recent.queries.queries_len >= 3,
        "FF_RECENT");
  xdr_free((xdrproc_t)xdr_ff_recent_reply, (char*)&recent);

  /* No --data-root: server-side loads are refused with a status and a message. */
  ff_load_args path = {(char*)"hills.pts", 0};
  memset(&load, 0, sizeof load);
  CHECK(ff_load_1(&path, &load, c) == RPC_SUCCESS && load.status == FF_ACCESS_DENIED &&
            strlen(load.message) > 0,
        "FF_LOAD refused with a message");
  xdr_free((xdrproc_t)xdr_ff_load_reply, (char*)&load);
  ff_load_options_args options;
  memset(&options, 0, sizeof options);
  options.path = (char*)"hills.obj";
  options.up_axis = 'y';
  memset(&load, 0, sizeof load);
  CHECK(ff_load_options_1(&options, &load, c) == RPC_SUCCESS && load.status == FF_ACCESS_DENIED,
        "FF_LOAD_OPTIONS refused with a status");
  xdr_free((xdrproc_t)xdr_ff_load_reply, (char*)&load);

  /* Full batches: FF_MAX_BATCH items, within one record fragment (send size below). */
  static ff_vec3 points[FF_MAX_BATCH];
  static ff_next_query queries[FF_MAX_BATCH];
  for (int i = 0; i < FF_MAX_BATCH; ++i) {
    ff_vec3 p = {i % 20, 1, (i / 20) % 20};
    points[i] = p;
    queries[i].foot = p;
    queries[i].direction.x = 1, queries[i].direction.y = 0, queries[i].direction.z = 0;
  }
  ff_point_batch_args batch = {terrain.terrain, {FF_MAX_BATCH, points}};
  ff_batch_reply answers;
  memset(&answers, 0, sizeof answers);
  CHECK(ff_snap_batch_1(&batch, &answers, c) == RPC_SUCCESS && answers.status == FF_OK &&
            answers.results.results_len == FF_MAX_BATCH,
        "FF_SNAP_BATCH of FF_MAX_BATCH points");
  xdr_free((xdrproc_t)xdr_ff_batch_reply, (char*)&answers);
  memset(&answers, 0, sizeof answers);
  CHECK(ff_normal_batch_1(&batch, &answers, c) == RPC_SUCCESS && answers.status == FF_OK &&
            answers.results.results_len == FF_MAX_BATCH,
        "FF_NORMAL_BATCH of FF_MAX_BATCH points");
  xdr_free((xdrproc_t)xdr_ff_batch_reply, (char*)&answers);
  ff_next_batch_args steps = {terrain.terrain, 0, {FF_MAX_BATCH, queries}};
  memset(&answers, 0, sizeof answers);
  CHECK(ff_next_batch_1(&steps, &answers, c) == RPC_SUCCESS && answers.status == FF_OK &&
            answers.results.results_len == FF_MAX_BATCH,
        "FF_NEXT_BATCH of FF_MAX_BATCH queries");
  xdr_free((xdrproc_t)xdr_ff_batch_reply, (char*)&answers);

  memset(&status, 0, sizeof status);
  CHECK(ff_unload_1(&terrain, &status, c) == RPC_SUCCESS && status.status == FF_OK, "FF_UNLOAD");
  xdr_free((xdrproc_t)xdr_ff_status_reply, (char*)&status);
#undef CHECK
}

int main(int argc, char** argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: plain_c_client PORT\n");
    return 2;
  }
  signal(SIGPIPE, SIG_IGN);
  const int port = atoi(argv[1]);
  struct timeval timeout = {10, 0};

  CLIENT* c = tcp_client(port, FOOTFALL_V1, FF_MAX_REQUEST_BYTES);
  check(c != NULL, "connect over TCP");
  if (!c) return 1;
  every_procedure(c, "AUTH_NONE");
  auth_destroy(c->cl_auth);
  c->cl_auth = authunix_create_default();
  every_procedure(c, "AUTH_SYS");

  /* An unknown procedure: PROC_UNAVAIL, and the connection serves on. */
  enum clnt_stat s = clnt_call(c, 17, XDR_VOID, NULL, XDR_VOID, NULL, timeout);
  check(s == RPC_PROCUNAVAIL, "procedure 17 is PROC_UNAVAIL");
  check(ff_null_1(NULL, NULL, c) == RPC_SUCCESS, "FF_NULL after an unknown procedure");
  auth_destroy(c->cl_auth); /* clnt_destroy leaves the AUTH_SYS handle */
  clnt_destroy(c);

  /* Version 2: PROG_MISMATCH, naming version 1 as the only one served. */
  c = tcp_client(port, 2, 0);
  check(c != NULL, "connect asking version 2");
  if (c) {
    s = clnt_call(c, 0, XDR_VOID, NULL, XDR_VOID, NULL, timeout);
    struct rpc_err e;
    clnt_geterr(c, &e);
    check(s == RPC_PROGVERSMISMATCH && e.re_vers.low == 1 && e.re_vers.high == 1,
          "version 2 is PROG_MISMATCH, versions 1 to 1");
    clnt_destroy(c);
  }

  /* UDP is not served: a datagram to the port is refused at once (ICMP), not timed out. */
  struct sockaddr_in a = address(port);
  int sock = RPC_ANYSOCK;
  struct timeval wait = {1, 0};
  c = clntudp_create(&a, FOOTFALL_PROG, FOOTFALL_V1, wait, &sock);
  if (c) {
    struct timeval two = {2, 0};
    s = clnt_call(c, 0, XDR_VOID, NULL, XDR_VOID, NULL, two);
    check(s == RPC_CANTRECV, "FF_NULL over UDP is refused (Unable to receive)");
    clnt_destroy(c);
  }
  return failures == 0 ? 0 : 1;
}
