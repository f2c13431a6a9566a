#!/usr/bin/env bash
# Regenerates tests/golden/rs274/*.canon from LinuxCNC's rs274 (Debian: linuxcnc-uspace),
# for the RS274NGC programs of ../shared/corpus/linuxcnc (those under 64 KB) and for
# ncplan's own test programs in tests/programs/linuxcnc (goldens named own__<name>).
# Each golden holds rs274's calls without their sequence prefix; if rs274 stops with an
# error (a non-zero exit), the last line is `# rs274 error: <message>`, the first line rs274
# wrote to stderr; (print,...) output is not an error.
# The corpus flattens LinuxCNC's test folders into file names (`a/b/test.ngc` is
# `a_b_test.ngc`, `a/b/subs/x.ngc` is `a_b_subs_x.ngc`), so each program runs in a scratch
# folder holding its siblings under their own names, where rs274 finds called subroutines.
set -euo pipefail
cd "$(dirname "$0")"
corpus=../../../shared/corpus/linuxcnc
out=rs274
tbl=$(mktemp)
scratch=$(mktemp -d)
trap 'rm -rf "$tbl" "$scratch"' EXIT
# An all-zero tool table, so that tool length offsets are 0 as in ncplan's empty table.
for i in $(seq 1 99); do echo "T$i P$i Z0 D0"; done > "$tbl"
rm -f "$out"/*.canon
for f in "$corpus"/*.ngc ../programs/linuxcnc/*.ngc; do
  [ "$(stat -c %s "$f")" -le 65536 ] || continue
  name=$(basename "$f" .ngc)
  case "$f" in ../programs/*) name="own__$name" ;; esac
  rm -rf "${scratch:?}"/*
  base=$(basename "$f")
  prefix=${base%_*}_
  case "$f" in ../programs/*) prefix=$base ;; esac
  for s in "$(dirname "$f")/$prefix"*; do
    [ -f "$s" ] || continue
    short=${s##*/"$prefix"}
    cp "$s" "$scratch/${short#subs_}"
  done
  cp "$f" "$scratch/$base"
  # rs274 prints calls and (print,...) output on stdout, and an error on stderr between
  # `executing` lines; it exits non-zero only on an error.
  rc=0
  (cd "$scratch" && timeout 20 rs274 -g -t "$tbl" "$base" < /dev/null > "$scratch/.out" 2> "$scratch/.err") || rc=$?
  {
    sed -n 's/^ *[0-9][0-9]* N[^ ]* //p' "$scratch/.out"
    if [ "$rc" -ne 0 ]; then
      err=$(grep -v -E '^(executing|$)' "$scratch/.err" | head -1 || true)
      printf '# rs274 error: %s\n' "${err:-exit status $rc}"
    fi
  } > "$out/$name.canon"
done
# Programs whose trace explodes (endless loops in rs274 tests) are not kept.
find "$out" -name "*.canon" -size +200k -delete
ls "$out" | wc -l
