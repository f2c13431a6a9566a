#!/bin/sh
# Writes the programs of this folder that SOURCES.tsv marks "text not committed" (no licence
# stated) beside their sidecars, from mirrors of their repositories (fetched with the
# workplace's fetch tool; nothing here fetches). The other rows are committed.
# Usage: extract.sh [MIRROR_ROOT]; exit 1 if a mirror or a commit is missing.
exec sh "$(dirname "$0")/../../extract_sources.sh" "$(dirname "$0")" "${1:-}" "text not committed"
