#!/bin/sh
# Writes the programs of this folder that SOURCES.tsv marks "text not committed" (no licence
# stated) beside their sidecars, from mirrors of their repositories (fetched with the
# workplace's fetch tool; nothing here fetches). The other rows are committed.
# Usage: extract.sh [MIRROR_ROOT]; exit 1 if a mirror or a commit is missing.
set -u
here=$(dirname "$0")
root=${1:-${NCPLAN_MIRRORS:-/work/.mirror}}
status=0
tail -n +2 "$here/SOURCES.tsv" | grep 'text not committed' | while IFS='	' read -r file repo path commit rest; do
  dir="$root/$(echo "$repo" | sed 's|/|+|')/repo"
  [ -d "$dir/.git" ] && dir="$dir/.git"
  if git --git-dir="$dir" cat-file -e "$commit:$path" 2>/dev/null; then
    git --git-dir="$dir" show "$commit:$path" > "$here/$file"
  else
    echo "missing: $repo $commit $path" >&2; exit 1
  fi
done || status=1
exit $status
