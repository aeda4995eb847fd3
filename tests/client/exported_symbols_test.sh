#!/usr/bin/env bash
# libfootfall.so exports exactly the functions footfall_c.h declares: it exported 800 more
# (footfall's C++, nlohmann JSON, std instantiations), and a host program defining one of those
# names (footfall::ReadPointFile) had its own function run inside ffc_load_file.
# Usage: exported_symbols_test.sh LIBFOOTFALL HEADER
set -u
lib=$1
header=$2
source "$(dirname "$0")/../support/cli_checks.sh"

nm -D --defined-only "$lib" | awk '{print $NF}' | sort -u > "$work/exported.txt"
grep -o '\bffc_[a-z_]*(' "$header" | tr -d '(' | sort -u > "$work/declared.txt"
check "the header declares the C ABI" [ "$(wc -l < "$work/declared.txt")" -ge 15 ]
check "exported: the header's functions, nothing else" \
  diff "$work/declared.txt" "$work/exported.txt"
# The SONAME's major version is the header's FFC_ABI_VERSION.
abi=$(sed -n 's/^#define FFC_ABI_VERSION \([0-9]*\).*/\1/p' "$header")
soname=$(objdump -p "$lib" | awk '$1 == "SONAME" {print $2}')
check "SONAME libfootfall.so.$abi, the header's ABI version ($soname)" [ "$soname" = "libfootfall.so.$abi" ]
finish
