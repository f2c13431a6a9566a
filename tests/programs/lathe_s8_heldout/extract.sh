#!/bin/sh
# Writes the held-back programs of this folder beside their sidecars, from mirrors of the
# repositories SOURCES.tsv names (fetched with the workplace's fetch tool; nothing here
# fetches). None of them states a licence, so their texts stay out of git (.gitignore).
# Usage: extract.sh [MIRROR_ROOT]; exit 1 if the mirror or the commit is missing.
exec sh "$(dirname "$0")/../extract_sources.sh" "$(dirname "$0")" "$@"
