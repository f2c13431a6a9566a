#!/bin/sh
# Rebuild the issue-43 sweep's program texts from repository mirrors (fetched with the
# workplace's fetch tool; nothing here fetches). Usage: extract.sh OUT [MIRROR_ROOT]
# Writes OUT/<id>.<ext> for every row of material.tsv; exit 1 if a mirror or commit is missing.
set -u
out=${1:?usage: extract.sh OUT [MIRROR_ROOT]}
root=${2:-${NCPLAN_MIRRORS:-/work/.mirror}}
here=$(dirname "$0")
mkdir -p "$out"
status=0
grep -v '^#' "$here/material.tsv" | tail -n +2 | while IFS='	' read -r id half repo commit path rest; do
  dir="$root/$(echo "$repo" | sed 's|/|+|')/repo"
  [ -d "$dir/.git" ] && dir="$dir/.git"
  ext=$(echo "${path##*.}" | tr 'A-Z' 'a-z')
  if ! git --git-dir="$dir" show "$commit:$path" > "$out/$id.$ext" 2>/dev/null; then
    echo "missing: $repo $commit $path" >&2; rm -f "$out/$id.$ext"; status=1
  fi
done
exit $status
