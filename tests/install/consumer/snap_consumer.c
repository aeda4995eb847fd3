/* Snaps one point with the installed C ABI and prints the answer's sample index and position.
   Usage: snap_consumer TERRAIN X Y Z */
#include <footfall/client/footfall_c.h>

#include <stdio.h>
#include <stdlib.h>

int main(int argc, char** argv) {
  ffc_session* session;
  uint32_t terrain = 0;
  double point[3];
  ffc_foothold answer;
  int i;
  if (argc != 5) {
    fprintf(stderr, "usage: snap_consumer TERRAIN X Y Z\n");
    return 1;
  }
  if (ffc_abi_version() != FFC_ABI_VERSION) {
    fprintf(stderr, "library ABI %d, header %d\n", ffc_abi_version(), FFC_ABI_VERSION);
    return 1;
  }
  for (i = 0; i < 3; ++i) point[i] = strtod(argv[2 + i], NULL);
  session = ffc_open_embedded();
  if (ffc_load_file(session, argv[1], 0.0, &terrain) != FF_C_OK ||
      ffc_snap(session, terrain, point, 1, &answer) != FF_C_OK || answer.status != FF_C_OK) {
    fprintf(stderr, "snap: %s\n", ffc_last_error(session));
    ffc_close(session);
    return 1;
  }
  printf("%u %.17g %.17g %.17g\n", (unsigned)answer.index, answer.point[0], answer.point[1],
         answer.point[2]);
  ffc_close(session);
  return 0;
}
