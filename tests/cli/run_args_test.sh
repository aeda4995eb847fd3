#!/usr/bin/env bash
# scripts/run.sh's arguments: the caller's flags replace the script's own of the same name (a
# second --path was refused by footfall generate; another terrain kept the hills' start).
source "$(dirname "$0")/../support/cli_checks.sh"
source "$1/scripts/main-job-args.sh"
args_are() {  # args_are NAME EXPECTED -- CALLER_ARGS...
  local name=$1 want=$2; shift 3
  main_job_arguments "$@"
  local got="${main_job_args[*]}"
  check "$name: '$got'" [ "$got" = "$want" ]
}
own_out="--out out/walk.json --out out/walk.gltf --out out/walk.mel"
args_are defaults "--terrain data/terrain/hills.pts --character data/characters/biped.json --start 8,0,8 --path 8,0,30 30,0,30 $own_out" --
args_are steps "--terrain data/terrain/hills.pts --character data/characters/biped.json --start 8,0,8 --path 8,0,30 30,0,30 $own_out --steps 40" -- --steps 40
args_are path "--terrain data/terrain/hills.pts --character data/characters/biped.json --start 8,0,8 $own_out --path 10,0,10 20,0,20" -- --path "10,0,10 20,0,20"
args_are heading "--terrain data/terrain/hills.pts --character data/characters/biped.json --start 8,0,8 $own_out --heading=1,0,0" -- --heading=1,0,0
args_are terrain "--character data/characters/biped.json $own_out --terrain data/terrain/stairs.pts" -- --terrain data/terrain/stairs.pts
args_are out "--terrain data/terrain/hills.pts --character data/characters/biped.json --start 8,0,8 --path 8,0,30 30,0,30 --out /tmp/w.json" -- --out /tmp/w.json
main_job_arguments --out x.json
check "out: the script's own outputs not announced" [ "$main_job_own_out" = false ]
finish
