# Runs the built `footfall` binary on good and bad terrain files and checks exit codes and
# messages. Usage: cmake -DFOOTFALL=path/to/footfall -DWORK=scratch-dir -P cli_test.cmake
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")

# expect(EXIT_ZERO|EXIT_NONZERO TEXT args...): runs footfall args, checks the exit code and that
# stdout+stderr contains TEXT.
function(expect want text)
  execute_process(COMMAND "${FOOTFALL}" ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out
                  ERROR_VARIABLE err INPUT_FILE "${WORK}/stdin.txt")
  set(all "${out}${err}")
  if(want STREQUAL "EXIT_ZERO" AND NOT rc EQUAL 0)
    message(FATAL_ERROR "footfall ${ARGN}: exit ${rc}, expected 0\n${all}")
  endif()
  if(want STREQUAL "EXIT_NONZERO" AND rc EQUAL 0)
    message(FATAL_ERROR "footfall ${ARGN}: exit 0, expected non-zero\n${all}")
  endif()
  string(FIND "${all}" "${text}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "footfall ${ARGN}: output lacks '${text}':\n${all}")
  endif()
endfunction()

file(WRITE "${WORK}/stdin.txt" "snap 0.5 2 0.5\n")
file(WRITE "${WORK}/cube.obj" "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
     "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n")
file(WRITE "${WORK}/empty.obj" "")
file(WRITE "${WORK}/nan.obj" "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n")
file(WRITE "${WORK}/fin.obj" "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n")
file(WRITE "${WORK}/cut.off" "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n")
file(WRITE "${WORK}/terrain.dae" "<COLLADA/>")
file(WRITE "${WORK}/empty.pts" "# no samples\n\n")
file(WRITE "${WORK}/far.pts" "0 0 0 0 1 0\n1e308 0 0 0 1 0\n")
file(WRITE "${WORK}/tall.asc" "ncols 2\nnrows 2\ncellsize 1\nNODATA_value -3.4e38\n1 -3.4e38\n1e20 2\n")
file(WRITE "${WORK}/hill.asc" "ncols 3\nnrows 3\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 1 1\n1 2 1\n1 1 1\n")

# A description that cannot be written (a full disk) is an error, not exit 0.
execute_process(COMMAND "${FOOTFALL}" terrain info "${WORK}/hill.asc" RESULT_VARIABLE rc
                OUTPUT_FILE /dev/full ERROR_VARIABLE err)
if(rc EQUAL 0 OR NOT err MATCHES "footfall terrain info: cannot write to stdout: No space left")
  message(FATAL_ERROR "terrain info to a full disk: exit ${rc}, '${err}'")
endif()

# Good files.
expect(EXIT_ZERO "faces: 6" terrain info "${WORK}/cube.obj" --separation 0.1)
expect(EXIT_ZERO "grid:" terrain info "${WORK}/cube.obj" --separation 0.1)
expect(EXIT_ZERO "format: heightmap" terrain info "${WORK}/hill.asc")
expect(EXIT_ZERO "wrote" terrain convert "${WORK}/cube.obj" --separation 0.1 -o "${WORK}/cube.pts")
expect(EXIT_ZERO "format: points" terrain info "${WORK}/cube.pts")
expect(EXIT_ZERO "wrote" terrain make blocks --size 4 --spacing 0.2 -o "${WORK}/blocks.pts")
expect(EXIT_ZERO "\"found\":true" query --terrain "${WORK}/cube.obj" --separation 0.1)
# Smooth normals stop at the cube's edges (--crease-angle, default 60): the top face's normal is
# straight up away from its centre; smoothed across every edge (180) it leans toward the corners.
file(WRITE "${WORK}/stdin.txt" "normal 0.25 1.05 0.25\n")
expect(EXIT_ZERO "\"normal\":[0.0,1.0,0.0]" query --terrain "${WORK}/cube.obj" --separation 0.1)
execute_process(COMMAND "${FOOTFALL}" query --terrain "${WORK}/cube.obj" --separation 0.1
                        --crease-angle 180
                RESULT_VARIABLE rc OUTPUT_VARIABLE out INPUT_FILE "${WORK}/stdin.txt")
if(NOT rc EQUAL 0 OR NOT out MATCHES "\"found\":true" OR out MATCHES "\"normal\":\\[0.0,1.0,0.0\\]")
  message(FATAL_ERROR "--crease-angle 180: expected a normal leaning off +y, got ${out}")
endif()
expect(EXIT_NONZERO "--crease-angle" query --terrain "${WORK}/cube.obj" --crease-angle 200)
# --flat-normals takes each face's normal even where corners are smoothed (--crease-angle 180);
# --smooth-normals is the default.
execute_process(COMMAND "${FOOTFALL}" query --terrain "${WORK}/cube.obj" --separation 0.1
                        --crease-angle 180 --flat-normals
                RESULT_VARIABLE rc OUTPUT_VARIABLE flat INPUT_FILE "${WORK}/stdin.txt")
if(NOT rc EQUAL 0 OR NOT flat MATCHES "\"normal\":\\[0.0,1.0,0.0\\]")
  message(FATAL_ERROR "--flat-normals: expected the top face's normal, got ${flat}")
endif()
execute_process(COMMAND "${FOOTFALL}" query --terrain "${WORK}/cube.obj" --separation 0.1
                        --crease-angle 180 --smooth-normals
                RESULT_VARIABLE rc OUTPUT_VARIABLE smooth INPUT_FILE "${WORK}/stdin.txt")
if(NOT rc EQUAL 0 OR NOT smooth STREQUAL out)
  message(FATAL_ERROR "--smooth-normals: expected the default's answer ${out}, got ${smooth}")
endif()
# A UTF-8 byte order mark (a file saved by a Windows editor) is skipped in OBJ and OFF files, as
# in point files: every vertex is read (it was refused; OpenMesh had lost the first vertex).
string(ASCII 239 187 191 bom)
file(WRITE "${WORK}/bom.obj" "${bom}v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 3 2\n")
expect(EXIT_ZERO "vertices: 3" terrain info "${WORK}/bom.obj")
file(WRITE "${WORK}/bom.off" "${bom}OFF\n3 1 0\n0 0 0\n1 0 0\n0 0 1\n3 0 2 1\n")
expect(EXIT_ZERO "vertices: 3" terrain info "${WORK}/bom.off")
# What is misread otherwise is refused with why: CR-only lines, an upper-case ASCII STL (read as
# binary).
file(WRITE "${WORK}/cr.obj" "v 0 0 0\rv 1 0 0\rv 0 0 1\rf 1 3 2\r")
expect(EXIT_NONZERO "cr.obj: lines end in CR alone" terrain info "${WORK}/cr.obj")
file(WRITE "${WORK}/upper.stl" "SOLID x\nfacet normal 0 1 0\nouter loop\nvertex 0 0 0\n"
     "vertex 1 0 0\nvertex 0 0 1\nendloop\nendfacet\nENDSOLID x\n")
expect(EXIT_NONZERO "upper.stl: an ASCII STL must begin with 'solid' in lower case"
       terrain info "${WORK}/upper.stl")
# A byte order mark before an ASCII STL's 'solid' or a PLY's 'ply' is named (the STL was called
# a truncated binary STL of billions of triangles, the PLY's first line not 'ply').
file(WRITE "${WORK}/bom.stl" "${bom}solid x\nfacet normal 0 1 0\nouter loop\nvertex 0 0 0\n"
     "vertex 1 0 0\nvertex 0 0 1\nendloop\nendfacet\nendsolid x\n")
expect(EXIT_NONZERO "bom.stl: starts with a UTF-8 byte order mark before 'solid'"
       terrain info "${WORK}/bom.stl")
file(WRITE "${WORK}/bom.ply" "${bom}ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
     "property float y\nproperty float z\nelement face 1\n"
     "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 0 1\n3 0 2 1\n")
expect(EXIT_NONZERO "bom.ply:1: starts with a UTF-8 byte order mark before 'ply'"
       terrain info "${WORK}/bom.ply")
# OFF counts on the header line and '#' comments (OpenMesh read no vertices, or bad faces), a
# PLY vertex list property (it read no faces), a binary STL longer than its triangles.
file(WRITE "${WORK}/oneline.off" "OFF 3 1 0\n0 0 0\n1 0 0\n0 0 1\n3 0 2 1\n")
expect(EXIT_NONZERO "oneline.off:1: expected the counts on the line after 'OFF'"
       terrain info "${WORK}/oneline.off")
file(WRITE "${WORK}/comment.off" "OFF\n3 1 0\n0 0 0\n# a comment\n1 0 0\n0 0 1\n3 0 2 1\n")
expect(EXIT_NONZERO "comment.off:4: a '#' comment, which footfall's OFF reader does not read"
       terrain info "${WORK}/comment.off")
file(WRITE "${WORK}/vlist.ply" "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
     "property float y\nproperty float z\nproperty list uchar float texcoord\nelement face 1\n"
     "property list uchar int vertex_indices\nend_header\n0 0 0 2 0 0\n1 0 0 2 1 0\n"
     "0 0 1 2 0 1\n3 0 2 1\n")
expect(EXIT_NONZERO "vlist.ply:7: vertex property 'texcoord' is a list"
       terrain info "${WORK}/vlist.ply")
# A height map's frame given for another kind of file is refused, not ignored.
expect(EXIT_NONZERO "applies to height maps (.asc .pgm) only, not to a mesh"
       terrain info "${WORK}/cube.obj" --height-scale 10)
expect(EXIT_NONZERO "applies to height maps (.asc .pgm) only, not to a point file"
       query --terrain "${SOURCE_DIR}/data/terrain/ramp.pts" --cell-size 2)
expect(EXIT_ZERO "format: heightmap" terrain info "${WORK}/hill.asc" --height-scale 2 --cell-size 3)
file(WRITE "${WORK}/stdin.txt" "snap 0.5 2 0.5\n")
# A cube wound inside out is turned over: its top's normal faces up.
file(READ "${WORK}/cube.obj" cube)
string(REPLACE "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n"
       "f 2 3 4 1\nf 8 7 6 5\nf 5 6 2 1\nf 6 7 3 2\nf 7 8 4 3\nf 8 5 1 4\n" inside_out "${cube}")
file(WRITE "${WORK}/inside_out.obj" "${inside_out}")
# The cube's 6 quads are 12 triangles: what was turned over is counted in triangles, not in
# the file's faces (the count read "12 faces" of a 6-face cube).
expect(EXIT_ZERO "faces turned over: 1 of 1 closed shells inside out: 12 triangles turned over"
       terrain info "${WORK}/inside_out.obj" --separation 0.1)
expect(EXIT_ZERO "faces turned over: none" terrain info "${WORK}/cube.obj" --separation 0.1)
# generate says so too at a --separation (it did only when it resampled the mesh itself).
file(WRITE "${WORK}/down.obj" "v 0 0 0\nv 10 0 0\nv 10 0 10\nv 0 0 10\nf 1 2 3 4\n")
expect(EXIT_ZERO "down.obj: the 2 triangles of its open parts faced down: 2 triangles turned over"
       generate --terrain "${WORK}/down.obj" --separation 0.5 --character
       "${SOURCE_DIR}/data/characters/biped.json" --steps 2 --out "${WORK}/down.json")
# Faces left out are said by convert and generate (convert said nothing of them, nor of faces
# turned over), and by generate both at a --separation and resampling for the character.
file(WRITE "${WORK}/left_out.obj"
     "v 0 0 0\nv 10 0 0\nv 10 0 10\nv 0 0 10\nv 20 0 0\nf 1 4 3 2\nf 1 1 2\nf 1 2 5\n")
expect(EXIT_ZERO "left_out.obj: 2 of 3 faces left out (a vertex used twice, a face listed again, or no area)"
       terrain convert "${WORK}/left_out.obj" --separation 0.5 -o "${WORK}/left_out.pts")
expect(EXIT_ZERO "down.obj: the 2 triangles of its open parts faced down: 2 triangles turned over"
       terrain convert "${WORK}/down.obj" --separation 0.5 -o "${WORK}/down.pts")
foreach(separation "--separation;0.5" "--seed;1")
  expect(EXIT_ZERO "left_out.obj: 2 of 3 faces left out"
         generate --terrain "${WORK}/left_out.obj" ${separation} --character
         "${SOURCE_DIR}/data/characters/biped.json" --steps 2 --out "${WORK}/left_out.json")
endforeach()
# One face wound against the others is counted in the singular.
string(REPLACE "f 1 4 3 2\n" "f 2 3 4 1\n" one_turned "${cube}")
file(WRITE "${WORK}/one_turned.obj" "${one_turned}")
expect(EXIT_ZERO "faces turned over: 1 face wound against its neighbours turned to match them"
       terrain info "${WORK}/one_turned.obj" --separation 0.1)
file(WRITE "${WORK}/stdin.txt" "normal 0.25 1.05 0.25\n")
expect(EXIT_ZERO "\"normal\":[0.0,1.0,0.0]" query --terrain "${WORK}/inside_out.obj" --separation 0.1)
file(WRITE "${WORK}/stdin.txt" "snap 0.5 2 0.5\n")
# Bad files: non-zero exit and a message naming the file and the problem.
expect(EXIT_NONZERO "empty.obj: the file is empty, expected a mesh (.obj)" terrain info "${WORK}/empty.obj")
expect(EXIT_NONZERO "nan.obj:2: vertex coordinate 'nan' is not a finite number"
       terrain convert "${WORK}/nan.obj" -o "${WORK}/nan.pts")
expect(EXIT_NONZERO "fin.obj: the mesh is not manifold" terrain info "${WORK}/fin.obj")
# Terrain is written as points: an output named like a mesh is refused, nothing written.
expect(EXIT_NONZERO "expected a point file name (.pts .xyz .txt)"
       terrain convert "${WORK}/cube.obj" --separation 0.1 -o "${WORK}/cube-out.obj")
expect(EXIT_NONZERO "expected a point file name (.pts .xyz .txt)"
       terrain make flat -o "${WORK}/flat.ply")
if(EXISTS "${WORK}/cube-out.obj" OR EXISTS "${WORK}/flat.ply")
  message(FATAL_ERROR "a terrain was written under a mesh file name")
endif()
expect(EXIT_NONZERO "cut.off: truncated: header declares 2 faces, found 1"
       terrain info "${WORK}/cut.off")
# A grid far narrower than its heights are tall (cells in degrees) is told about --cell-size.
file(WRITE "${WORK}/degrees.asc" "ncols 3\nnrows 3\nxllcorner -105\nyllcorner 40\ncellsize 0.0001\n0 1000 0\n1000 0 1000\n0 1000 0\n")
expect(EXIT_NONZERO "give --cell-size in the heights' units" terrain info "${WORK}/degrees.asc")
# So is generate, which resamples it finer for a character and finds its triangles thin.
expect(EXIT_NONZERO "if its cells are in degrees, as a geographic grid's, give --cell-size"
       generate --terrain "${WORK}/degrees.asc" --character "${SOURCE_DIR}/data/characters/biped.json"
       --out "${WORK}/degrees.json")
# terrain make: every number finite, and a cap on the samples before anything is allocated.
expect(EXIT_NONZERO "--amplitude: 'nan' is not a finite number"
       terrain make hills --amplitude nan -o "${WORK}/x.pts")
expect(EXIT_NONZERO "--amplitude: 'inf' is not a finite number"
       terrain make rocks --amplitude inf -o "${WORK}/x.pts")
expect(EXIT_NONZERO "--spacing: 'nan' is not a finite number > 0"
       terrain make flat --spacing nan -o "${WORK}/x.pts")
expect(EXIT_NONZERO "--slope: '1e300' is not a finite number from -80 to 80"
       terrain make ramp --slope 1e300 -o "${WORK}/x.pts")
expect(EXIT_NONZERO "hills: these sizes at --spacing 0.05 give about 4000004000001 samples, more than the 20000000 allowed"
       terrain make hills --size 100000 -o "${WORK}/x.pts")
expect(EXIT_NONZERO "flat: these sizes at --spacing 1e-300 give too many samples, more than"
       terrain make flat --spacing 1e-300 -o "${WORK}/x.pts")
expect(EXIT_NONZERO "flat: these sizes at --spacing 0.001 give about 4e+24 samples"
       terrain make flat --size 2000000000 --spacing 0.001 -o "${WORK}/x.pts")
# A coarse spacing does not make the work small: a tread takes a sample however coarse it is
# (this ran out of memory making 4 billion samples), rocks are modelled 0.25 apart and blocks
# one unit cube at a time whatever the spacing (these ran for minutes, or out of memory).
expect(EXIT_NONZERO "stairs: these sizes at --spacing 1e+12 give about 4294967294 samples, more than the 20000000 allowed"
       terrain make stairs --steps 2147483647 --spacing 1e12 -o "${WORK}/x.pts")
expect(EXIT_NONZERO "rocks: these sizes give a mesh of about 64000000 cells to sample (rocks are modelled 0.25 apart, whatever --spacing), more than the 20000000 allowed"
       terrain make rocks --size 2000 --spacing 10 -o "${WORK}/x.pts")
expect(EXIT_NONZERO "blocks: these sizes give a mesh of about 1236950580816 cells to sample (a face per side of a unit cube)"
       terrain make blocks --max-height 2147483647 --spacing 1e6 -o "${WORK}/x.pts")
# Sizes far beyond the grid's range are refused as such, whatever the spacing (a sphere of
# radius 1e300 at --spacing 1e300 was "about -nan samples").
expect(EXIT_NONZERO "sphere: the parameters give coordinates beyond 5e+14"
       terrain make sphere --radius 1e300 --spacing 1e300 -o "${WORK}/x.pts")
# A mesh the sampler refuses says why (it was "the parameters give no samples").
expect(EXIT_NONZERO "rocks: separation 0.5 would give about "
       terrain make rocks --size 2 --spacing 0.5 --amplitude 4e14 -o "${WORK}/x.pts")
expect(EXIT_NONZERO "--height-scale: 'nan' is not a finite number"
       terrain info "${WORK}/hill.asc" --height-scale nan)
if(EXISTS "${WORK}/x.pts")
  message(FATAL_ERROR "terrain make wrote a file for bad flags")
endif()
# A point file without samples is refused by every command that loads it.
foreach(command "terrain;info" "query;--terrain" "generate;--character;${SOURCE_DIR}/data/characters/biped.json;--out;${WORK}/x.json;--terrain")
  expect(EXIT_NONZERO "empty.pts: no samples (expected at least one line x y z nx ny nz)"
         ${command} "${WORK}/empty.pts")
endforeach()
expect(EXIT_NONZERO "far.pts:2: column 1: 1e308 is out of range (expected |x| <= 5e+14)"
       terrain info "${WORK}/far.pts")
# NODATA may be huge; a valid height beyond the grid's range is refused with its line.
expect(EXIT_NONZERO "tall.asc:6: value 1e20 is out of range (expected |height| <= 5e+14)"
       terrain info "${WORK}/tall.asc")
expect(EXIT_NONZERO "hill.asc: cell (row 0, column 0): height 1 x 1e+15 is out of range (expected |height| <= 5e+14)"
       terrain info "${WORK}/hill.asc" --height-scale 1e15)
expect(EXIT_NONZERO "hill.asc: the grid spans 2e+15"
       terrain info "${WORK}/hill.asc" --cell-size 1e15)
expect(EXIT_NONZERO "unknown terrain file extension 'dae'" terrain info "${WORK}/terrain.dae")
expect(EXIT_NONZERO "absent.obj: cannot open" query --terrain "${WORK}/absent.obj")
expect(EXIT_NONZERO "choose a separation of at least" terrain info "${WORK}/cube.obj" --separation 0.0001)
# Stairs going down along +z (a negative rise): their risers face +z (they were left out).
expect(EXIT_ZERO "wrote" terrain make stairs --steps 3 --rise -0.2 --spacing 0.05 -o "${WORK}/down.pts")
file(WRITE "${WORK}/riser.txt" "snap 0.5 -0.1 0.35\n")
execute_process(COMMAND "${FOOTFALL}" query --terrain "${WORK}/down.pts" INPUT_FILE "${WORK}/riser.txt"
                OUTPUT_VARIABLE riser RESULT_VARIABLE rc)
if(NOT rc EQUAL 0 OR NOT riser MATCHES "\"normal\":\\[0\\.0,0\\.0,1\\.0\\]")
  message(FATAL_ERROR "the riser of stairs going down does not face +z: ${riser}")
endif()
file(STRINGS "${WORK}/down.pts" negative_zero REGEX "(^| )-0( |$)")
if(negative_zero)
  message(FATAL_ERROR "stairs going down written with -0: ${negative_zero}")
endif()
# terrain make hills makes the same hills at any spacing: the sample at (2, 2) of a 0.05 m and a
# 0.2 m lattice has the same height and normal (the relief was laid in sample units: 0.14 m at
# one spacing, -0.12, -0.95 and 0.49 at others).
foreach(spacing 0.05 0.2)
  expect(EXIT_ZERO "wrote" terrain make hills --size 4 --spacing ${spacing} -o "${WORK}/hills${spacing}.pts")
  file(STRINGS "${WORK}/hills${spacing}.pts" at22 REGEX "^2 [^ ]+ 2 ")
  list(LENGTH at22 found)
  if(NOT found EQUAL 1)
    message(FATAL_ERROR "hills at ${spacing}: no single sample at x = 2, z = 2: ${at22}")
  endif()
  string(REPLACE " " ";" fields "${at22}")
  list(GET fields 1 y${spacing})
  list(GET fields 4 ny${spacing})
endforeach()
if(NOT y0.05 STREQUAL y0.2 OR NOT ny0.05 STREQUAL ny0.2)
  message(FATAL_ERROR "hills differ with the spacing at (2, 2): y ${y0.05} / ${y0.2}, ny ${ny0.05} / ${ny0.2}")
endif()
# Seeds are whole numbers from 0 to 2^64 - 1 everywhere (make read -1 and 1e23 as 2^64 - 1).
foreach(seed "-1" "18446744073709551616" "1.5")
  expect(EXIT_NONZERO "--seed: '${seed}' is not a whole number from 0 to 18446744073709551615"
         terrain make hills --seed ${seed} -o "${WORK}/x.pts")
endforeach()
# convert --character: as fine as a quarter of the step, and said when the sample limit of a
# walk's terrain makes it coarser (a 1 mm step on a 10 m square).
file(READ "${SOURCE_DIR}/data/characters/biped.json" biped)
string(REPLACE "\"step_length\": 0.7" "\"step_length\": 0.004" tiny "${biped}")
file(WRITE "${WORK}/tiny.json" "${tiny}")
file(WRITE "${WORK}/square.obj" "v 0 0 0\nv 10 0 0\nv 10 0 10\nv 0 0 10\nf 1 4 3 2\n")
execute_process(COMMAND "${FOOTFALL}" terrain convert "${WORK}/square.obj" --character "${WORK}/tiny.json"
                -o "${WORK}/square.pts" RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT err MATCHES "footfall terrain convert: not finer than 0\\.0[0-9]+ \\([0-9.]+ times a quarter of the step\\)")
  message(FATAL_ERROR "convert --character past the sample limit: exit ${rc}, '${out}' '${err}'")
endif()
execute_process(COMMAND "${FOOTFALL}" terrain convert "${WORK}/square.obj" --character
                "${SOURCE_DIR}/data/characters/biped.json" -o "${WORK}/square.pts"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "separation 0\\.17" OR NOT err STREQUAL "")
  message(FATAL_ERROR "convert --character within the limit: exit ${rc}, '${out}' '${err}'")
endif()
# --scale scales the character as generate's does: twice the biped, twice the separation.
execute_process(COMMAND "${FOOTFALL}" terrain convert "${WORK}/square.obj" --character
                "${SOURCE_DIR}/data/characters/biped.json" --scale 2 -o "${WORK}/square.pts"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "separation 0\\.35" OR NOT err STREQUAL "")
  message(FATAL_ERROR "convert --character --scale 2: exit ${rc}, '${out}' '${err}'")
endif()
expect(EXIT_NONZERO "--scale: '0' is not a finite number from 1e-06 to 1e+06"
       terrain convert "${WORK}/square.obj" --character "${SOURCE_DIR}/data/characters/biped.json"
       --scale 0 -o "${WORK}/square.pts")
# convert never writes over its input; --separation with a point file is refused, not ignored.
file(WRITE "${WORK}/two.pts" "# surveyed\n0 0 0 0 1 0\n1 0 0 0 1 0\n")
expect(EXIT_NONZERO "two.pts: the output is the input file"
       terrain convert "${WORK}/two.pts" -o "${WORK}/two.pts")
file(READ "${WORK}/two.pts" kept)
if(NOT kept MATCHES "# surveyed")
  message(FATAL_ERROR "terrain convert wrote over its input")
endif()
expect(EXIT_ZERO "wrote 2 samples to" terrain convert "${WORK}/two.pts" -o "${WORK}/two-out.pts")
# Nor over its --character file, by name or through a link (the character was replaced by
# points, exit 0).
file(COPY "${SOURCE_DIR}/data/characters/biped.json" DESTINATION "${WORK}/own")
file(CREATE_LINK "${WORK}/own/biped.json" "${WORK}/own/link.pts" SYMBOLIC)
file(COPY_FILE "${SOURCE_DIR}/data/characters/biped.json" "${WORK}/own/char.pts")
foreach(pair "biped.json;link.pts" "char.pts;char.pts")
  list(GET pair 0 character)
  list(GET pair 1 output)
  expect(EXIT_NONZERO "${output}: the output is the character file --character reads"
         terrain convert "${WORK}/square.obj" --character "${WORK}/own/${character}"
         -o "${WORK}/own/${output}")
endforeach()
file(READ "${WORK}/own/biped.json" kept)
file(READ "${WORK}/own/char.pts" kept_pts)
if(NOT kept MATCHES "\"step_length\"" OR NOT kept_pts MATCHES "\"step_length\"")
  message(FATAL_ERROR "terrain convert wrote over its character file")
endif()
file(WRITE "${WORK}/one.pts" "0 0 0 0 1 0\n")
expect(EXIT_ZERO "wrote 1 sample to" terrain convert "${WORK}/one.pts" -o "${WORK}/one-out.pts")
# Samples at one point have no spacing (it read "about 1"); two apart have one.
expect(EXIT_ZERO "sample spacing: none (a single sample)" terrain info "${WORK}/one.pts")
file(WRITE "${WORK}/same.pts" "1 2 3 0 1 0\n1 2 3 0 0 1\n")
expect(EXIT_ZERO "sample spacing: none (every sample at one point)" terrain info "${WORK}/same.pts")
# Two samples 1 apart: too few to take as a surface (it read "about 0.07").
expect(EXIT_ZERO "sample spacing: about 1 (the median distance from a sample to its nearest)"
       terrain info "${WORK}/two.pts")
expect(EXIT_NONZERO "two.pts: --character applies to meshes and height maps, which are resampled for it; a point file is used as it is (leave --character out)"
       terrain convert "${WORK}/two.pts" --character "${SOURCE_DIR}/data/characters/biped.json" -o "${WORK}/two-c.pts")
foreach(command "terrain;info" "query;--terrain")
  expect(EXIT_NONZERO "two.pts: --separation applies to meshes and height maps, which are resampled; a point file is used as it is (leave --separation out)"
         ${command} "${WORK}/two.pts" --separation 0.1)
  # The other resampling flags too (they were ignored).
  expect(EXIT_NONZERO "two.pts: --flat-normals, --crease-angle and --seed apply to meshes and height maps"
         ${command} "${WORK}/two.pts" --flat-normals --crease-angle 30 --seed 4)
  expect(EXIT_NONZERO "two.pts: --up-axis applies to meshes and height maps"
         ${command} "${WORK}/two.pts" --up-axis z)
endforeach()
# Bounds far from the origin keep their digits.
file(WRITE "${WORK}/far_bulk.pts" "10000000.125 0 0 0 1 0\n10000000.5 0 1 0 1 0\n")
expect(EXIT_ZERO "bounds: (10000000.125, 0, 0) to (10000000.5, 0, 1)" terrain info "${WORK}/far_bulk.pts")
expect(EXIT_NONZERO "would give more than 1e+308 samples"
       terrain info "${WORK}/cube.obj" --separation 1e-300)
# Height map headers: each key once, its number on its own line, cellsize with its line.
file(WRITE "${WORK}/twice.asc" "ncols 2\nnrows 2\ncellsize 1\ncellsize 2\n1 2\n3 4\n")
expect(EXIT_NONZERO "twice.asc:4: header 'cellsize' given again (first on line 3)"
       terrain info "${WORK}/twice.asc")
file(WRITE "${WORK}/bare.asc" "ncols 2\nnrows 2\ncellsize 1\nNODATA_value\n1 2\n3 4\n")
expect(EXIT_NONZERO "bare.asc:4: header 'NODATA_value' needs a number on its line"
       terrain info "${WORK}/bare.asc")
file(WRITE "${WORK}/neg.asc" "ncols 2\nnrows 2\ncellsize -1\n1 2\n3 4\n")
expect(EXIT_NONZERO "neg.asc:3: cellsize -1 (expected a number > 0; or give a cell size of your own, --cell-size)" terrain info "${WORK}/neg.asc")
# --cell-size overrides a bad, missing or not square cell size (all were refused with it).
file(WRITE "${WORK}/nocell.asc" "ncols 2\nnrows 2\n1 2\n3 4\n")
file(WRITE "${WORK}/dxdy.asc" "ncols 2\nnrows 2\nDX 1\nDY 2\n1 2\n3 4\n")
foreach(grid neg nocell dxdy)
  expect(EXIT_ZERO "wrote 4 samples to" terrain convert "${WORK}/${grid}.asc" --cell-size 2
         -o "${WORK}/${grid}.pts")
endforeach()
file(STRINGS "${WORK}/nocell.pts" nocell_lines REGEX "^1\\.[5-9]")
if(NOT nocell_lines)
  message(FATAL_ERROR "--cell-size 2 over a grid without cellsize: no sample past x = 1.5")
endif()
string(ASCII 27 escape)
file(WRITE "${WORK}/esc.asc" "ncols 2\nnrows 2\ncellsize 1\n1 2\n3 ${escape}]0x\n")
expect(EXIT_NONZERO "esc.asc:5: value '?]0x' is not a finite number" terrain info "${WORK}/esc.asc")
# A height map far steeper than ground (cells 1 apart under heights in tens: a .pgm of an SRTM
# tile in metres) is said, naming --cell-size; with a cell size that fits, it is not. Loaded all
# the same (exit 0).
file(WRITE "${WORK}/steep.pgm" "P2\n3 3\n90\n0 40 80\n10 50 90\n0 40 80\n")
expect(EXIT_ZERO "steep.pgm: its surface is 41.2 times the area it covers (slopes of about 88.6 degrees on average, steeper than ground): its cells, 1 apart, are likely not in its heights' unit"
       terrain info "${WORK}/steep.pgm")
expect(EXIT_ZERO "give --cell-size in the heights' unit, or --height-scale" terrain info "${WORK}/steep.pgm")
execute_process(COMMAND "${FOOTFALL}" terrain info "${WORK}/steep.pgm" --cell-size 90
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT err STREQUAL "" OR NOT out MATCHES "surface over area covered: 1\\.")
  message(FATAL_ERROR "steep.pgm with --cell-size 90: exit ${rc}, '${out}' '${err}'")
endif()
expect(EXIT_ZERO "steep.pgm: its surface is" terrain convert "${WORK}/steep.pgm" -o "${WORK}/steep.pts")
file(WRITE "${WORK}/more.pgm" "P2\n2 2\n9\n1 2\n3 4 5\n")
expect(EXIT_NONZERO "more.pgm:5: more than the 4 grey levels the header declares"
       terrain info "${WORK}/more.pgm")
# A sampling the process's memory cannot hold is refused at once, saying so (it ran out of
# memory after seconds with a bare message).
file(WRITE "${WORK}/floor.obj" "v 0 0 0\nv 0 0 100\nv 100 0 100\nv 100 0 0\nf 1 2 3 4\n")
execute_process(COMMAND sh -c "ulimit -v 1500000 && exec \"$0\" terrain info \"$1\" --separation 0.03"
                        "${FOOTFALL}" "${WORK}/floor.obj"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc EQUAL 0 OR NOT err MATCHES "what this process's memory holds while sampling")
  message(FATAL_ERROR "a sampling beyond memory was not refused up front (exit ${rc}):\n${out}${err}")
endif()
file(REMOVE_RECURSE "${WORK}")
