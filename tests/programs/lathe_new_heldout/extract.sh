#!/bin/sh
# Writes the held-back programs of this folder beside their sidecars, from a mirror of
# enier290188/cnc (fetched with the workplace's fetch tool; nothing here fetches). Their
# repository states no licence, so their texts stay out of git (.gitignore).
# Usage: extract.sh [MIRROR_ROOT]; exit 1 if the mirror or the commit is missing.
exec sh "$(dirname "$0")/../extract_sources.sh" "$(dirname "$0")" "$@"
