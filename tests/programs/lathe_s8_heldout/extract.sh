#!/bin/sh
# Writes the held-back programs of this folder beside their sidecars, from mirrors of the
# repositories SOURCES.tsv names (fetched with the workplace's fetch tool; nothing here
# fetches). None of them states a licence, so their texts stay out of git (.gitignore).
# Usage: extract.sh [MIRROR_ROOT]; exit 1 if the mirror or the commit is missing.
set -u
here=$(dirname "$0")
root=${1:-${NCPLAN_MIRRORS:-/work/.mirror}}
status=0
tail -n +2 "$here/SOURCES.tsv" | while IFS='	' read -r file repo path commit rest; do
  dir="$root/$(echo "$repo" | sed 's|/|+|')/repo"
  [ -d "$dir/.git" ] && dir="$dir/.git"
  if git --git-dir="$dir" cat-file -e "$commit:$path" 2>/dev/null; then
    git --git-dir="$dir" show "$commit:$path" > "$here/$file"
  else
    echo "missing: $repo $commit $path" >&2; exit 1
  fi
done || status=1
exit $status
