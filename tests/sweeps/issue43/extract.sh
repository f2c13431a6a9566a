#!/bin/sh
# Rebuild the issue-43 sweep's program texts from repository mirrors (fetched with the
# workplace's fetch tool; nothing here fetches). Usage: extract.sh OUT [MIRROR_ROOT]
# Writes OUT/<owner+name>/<path> for every row of material.tsv, with the other files of the
# row's folder beside it (the programs it calls); exit 1 if a mirror or commit is missing.
set -u
out=${1:?usage: extract.sh OUT [MIRROR_ROOT]}
root=${2:-${NCPLAN_MIRRORS:-/work/.mirror}}
here=$(dirname "$0")
mkdir -p "$out"
grep -v '^#' "$here/material.tsv" | tail -n +2 | {
status=0
while IFS='	' read -r id half repo commit path rest; do
  key=$(echo "$repo" | sed 's|/|+|')
  dir="$root/$key/repo"
  [ -d "$dir/.git" ] && dir="$dir/.git"
  folder=$(dirname "$path")/
  [ "$folder" = "./" ] && folder=.
  if ! git --git-dir="$dir" cat-file -e "$commit:$path" 2>/dev/null; then
    echo "missing: $repo $commit $path" >&2; status=1; continue
  fi
  git -c core.quotepath=off --git-dir="$dir" ls-tree --name-only "$commit" "$folder" | while IFS= read -r p; do
    [ "$(git --git-dir="$dir" cat-file -t "$commit:$p")" = blob ] || continue
    mkdir -p "$out/$key/$(dirname "$p")"
    git --git-dir="$dir" show "$commit:$p" > "$out/$key/$p"
  done
  # A LinuxCNC configuration lays its INI out above the program folder (config/x.ini,
  # config/nc_files/part.ngc), with the remap subroutines in the folders its SUBROUTINE_PATH
  # names relative to it: keep those INIs (the folder above and the one above that) and folders.
  up=$(dirname "$path")
  for _ in 1 2; do
    [ "$up" = . ] && break
    up=$(dirname "$up")
    [ "$up" = . ] && pre= || pre="$up/"
    git -c core.quotepath=off --git-dir="$dir" ls-tree --name-only "$commit" ${pre:+"$pre"} | grep -i '\.ini$' | while IFS= read -r ini; do
      mkdir -p "$out/$key/$(dirname "$ini")"
      git --git-dir="$dir" show "$commit:$ini" > "$out/$key/$ini"
      sed -n 's/^[ \t]*SUBROUTINE_PATH[ \t]*=[ \t]*//p' "$out/$key/$ini" | tr ':' '\n' | tr -d '\r' | while IFS= read -r sp; do
        case "$sp" in ''|.|/*|~*) continue ;; esac
        git -c core.quotepath=off --git-dir="$dir" ls-tree --name-only "$commit" "$pre$sp/" | while IFS= read -r f; do
          [ "$(git --git-dir="$dir" cat-file -t "$commit:$f")" = blob ] || continue
          mkdir -p "$out/$key/$(dirname "$f")"
          git --git-dir="$dir" show "$commit:$f" > "$out/$key/$f"
        done
      done
    done
  done
done
exit $status
}
