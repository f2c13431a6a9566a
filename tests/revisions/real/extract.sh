#!/usr/bin/env bash
# Extract the real revision pairs described by the *.toml files beside this script
# from local git mirrors into a scratch directory.
#
#   tests/revisions/real/extract.sh OUT_DIR [MIRROR_ROOT]
#
# For every <id>.toml it writes OUT_DIR/<id>/original.<ext> (the file at `before`)
# and OUT_DIR/<id>/edited.<ext> (the file at `after`), <ext> being the lowercased
# extension of `path`. The bytes are written exactly as stored in git (line endings,
# encodings and a missing final newline are kept).
#
# MIRROR_ROOT (default /work/.mirror, or $NCPLAN_MIRRORS) holds one directory per
# repository, named owner+name, with the bare git directory in repo/ or repo/.git/
# (the layout the workplace's fetch tool produces). This script fetches nothing and
# builds nothing: a pair whose mirror or commit is missing is skipped with a message.
# Beside the pair, OUT_DIR/<id>/before/ and after/ hold the other files of the program's
# directory and its subfolders (two levels) with its extension at each commit: the subroutines it may call from other files,
# as a daemon watching that folder sees them.
# Exit status: 0 if every pair was extracted, 1 if any was skipped.
set -u
here=$(cd "$(dirname "$0")" && pwd)
out=${1:?usage: extract.sh OUT_DIR [MIRROR_ROOT]}
mirrors=${2:-${NCPLAN_MIRRORS:-/work/.mirror}}
mkdir -p "$out"

# value of a top-level `key = "string"` line of a TOML file
field() { sed -n "s/^$1 *= *\"\(.*\)\" *\$/\1/p" "$2" | head -n1 | sed 's/\\"/"/g; s/\\\\/\\/g'; }

ok=0; skipped=0
for toml in "$here"/*.toml; do
  id=$(basename "$toml" .toml)
  repo=$(field repo "$toml"); path=$(field path "$toml")
  before=$(field before "$toml"); after=$(field after "$toml")
  if [ -z "$repo" ] || [ -z "$path" ] || [ -z "$before" ] || [ -z "$after" ]; then
    echo "skip $id: incomplete toml" >&2; skipped=$((skipped+1)); continue
  fi
  base="$mirrors/${repo/\//+}/repo"
  if [ -d "$base/.git" ]; then gitdir="$base/.git"; elif [ -d "$base" ]; then gitdir="$base"; else
    echo "skip $id: no mirror of $repo at $base" >&2; skipped=$((skipped+1)); continue
  fi
  name=$(basename "$path")
  case "$name" in *.*) ext=$(printf '%s' "${name##*.}" | tr 'A-Z' 'a-z');; *) ext=txt;; esac
  mkdir -p "$out/$id"
  if git --git-dir="$gitdir" show "$before:$path" > "$out/$id/original.$ext" 2>/dev/null &&
     git --git-dir="$gitdir" show "$after:$path" > "$out/$id/edited.$ext" 2>/dev/null; then
    ok=$((ok+1))
    # The programs beside it, as a daemon watching its folder sees them: the other files of
    # the program's directory with its extension, at each commit (`before/`, `after/`), for
    # the subroutines it calls from other files.
    dir=$(dirname "$path"); [ "$dir" = . ] && dir=
    for side in before after; do
      commit=$before; [ "$side" = after ] && commit=$after
      rm -rf "${out:?}/$id/$side"; mkdir -p "$out/$id/$side"
      # Its subfolders too (`utilitysubs/loadtool.ngc` beside ngcgui's programs), as the
      # daemon watching the folder holds them, paths kept.
      git --git-dir="$gitdir" ls-tree -r "$commit" ${dir:+-- "$dir/"} 2>/dev/null | sed -n 's/^[0-9]* blob [0-9a-f]*	//p' |
        while IFS= read -r f; do
          b=$(basename "$f")
          rel=${f#"$dir/"}; [ -z "$dir" ] && rel=$f
          [ "$rel" = "$name" ] && continue
          # Two levels of subfolders at most, as ncplan looks (`config::SUBFOLDER_DEPTH`).
          case "$rel" in */*/*/*) continue;; esac
          # Files of its extension; for a program without one (LNC's `LOADTOOL`), the others
          # without one.
          case "$b" in
            *.*) case "$name" in *.*) ;; *) continue;; esac
                 [ "$(printf '%s' "${b##*.}" | tr 'A-Z' 'a-z')" = "$ext" ] || continue;;
            *) case "$name" in *.*) continue;; esac;;
          esac
          mkdir -p "$(dirname "$out/$id/$side/$rel")"
          git --git-dir="$gitdir" cat-file -e "$commit:$f" 2>/dev/null && git --git-dir="$gitdir" show "$commit:$f" > "$out/$id/$side/$rel" 2>/dev/null
        done
    done
  else
    echo "skip $id: $repo has no $path at $before or $after" >&2
    rm -rf "${out:?}/$id"; skipped=$((skipped+1))
  fi
done
echo "extracted $ok pairs into $out, skipped $skipped"
[ "$skipped" -eq 0 ]
