#!/bin/sh
# Entry point of the simulator and stub images: `python -m $HLVS_MODULE ARGS...`.
# A command that names a program on PATH (e.g. `python3 -m simulator run ...` or `sh -c ...`)
# is run as given, so both `docker run IMAGE run --spec ...` and full commands work.
set -e
if [ "$#" -gt 0 ] && command -v "$1" >/dev/null 2>&1; then
    exec "$@"
fi
exec python -m "${HLVS_MODULE:?HLVS_MODULE is not set}" "$@"
