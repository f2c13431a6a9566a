#!/bin/sh
# Writes the programs a folder's SOURCES.tsv lists (columns: file, repository, path, commit)
# beside their sidecars, from mirrors of their repositories (fetched with the workplace's
# fetch tool; nothing here fetches). Programs whose repository states no licence stay out of
# git (each folder's .gitignore); the held-back folders' extract.sh call this.
# Usage: extract_sources.sh FOLDER [MIRROR_ROOT] [ROW_PATTERN]: only the rows matching
# ROW_PATTERN (grep) when given; exit 1 if a mirror or a commit is missing.
set -u
here=$1
root=${2:-${NCPLAN_MIRRORS:-/work/.mirror}}
pattern=${3:-}
status=0
tail -n +2 "$here/SOURCES.tsv" | grep -e "$pattern" | while IFS='	' read -r file repo path commit rest; do
  dir="$root/$(echo "$repo" | sed 's|/|+|')/repo"
  [ -d "$dir/.git" ] && dir="$dir/.git"
  if git --git-dir="$dir" cat-file -e "$commit:$path" 2>/dev/null; then
    git --git-dir="$dir" show "$commit:$path" > "$here/$file"
  else
    echo "missing: $repo $commit $path" >&2; exit 1
  fi
done || status=1
exit $status
