# The arguments scripts/run.sh gives `footfall generate`: its own (the biped across the bundled
# hills, written under out/), each replaced by the caller's flag of that name. Sourced; sets
# `main_job_args` (the arguments, the caller's last) and `main_job_own_out` (true when the
# outputs are the script's own out/walk.*).
#   main_job_arguments "$@"
main_job_arguments() {
  local -a extra=("$@")
  given() {  # given FLAG...: true when an extra argument is one of the flags (or FLAG=VALUE)
    local arg flag
    for arg in "${extra[@]}"; do
      for flag in "$@"; do [[ $arg == "$flag" || $arg == "$flag="* ]] && return 0; done
    done
    return 1
  }
  main_job_args=()
  # The start and path are the hills': another terrain goes without them (its default start).
  local own_terrain=true
  if given --terrain --server-terrain; then
    own_terrain=false
  else
    main_job_args+=(--terrain data/terrain/hills.pts)
  fi
  given --character || main_job_args+=(--character data/characters/biped.json)
  if $own_terrain && ! given --start; then main_job_args+=(--start 8,0,8); fi
  if $own_terrain && ! given --path --heading; then main_job_args+=(--path "8,0,30 30,0,30"); fi
  main_job_own_out=true
  if given --out; then main_job_own_out=false; fi
  if $main_job_own_out; then
    main_job_args+=(--out out/walk.json --out out/walk.gltf --out out/walk.mel)
  fi
  main_job_args+=("$@")
}
