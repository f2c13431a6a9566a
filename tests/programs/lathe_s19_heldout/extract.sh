#!/bin/sh
# Writes the held-back programs of this folder beside their sidecars, from mirrors of the
# repositories SOURCES.tsv names (fetched with the workplace's fetch tool; nothing here
# fetches). Their texts stay out of git (.gitignore): their repositories state no licence.
# Usage: extract.sh [MIRROR_ROOT]; exit 1 if the mirror or the commit is missing.
exec sh "$(dirname "$0")/../extract_sources.sh" "$(dirname "$0")" "$@"
