#!/usr/bin/env bash
# Automated test matches: submit, wait for the end, download results and logs, then let your
# own step look at them before the next round. No error handling beyond stopping at the first
# failure; adapt it to your needs.
#
#   HLVS_SERVER=https://league.example.org HLVS_TOKEN=hlvs_... ./auto_submit.sh team_config.json 3
set -euo pipefail
team_config=${1:?usage: auto_submit.sh TEAM_CONFIG.json [ROUNDS]}
rounds=${2:-1}
: "${HLVS_SERVER:?set HLVS_SERVER to the service URL}"
for round in $(seq 1 "$rounds"); do
  # --wait polls until the match has ended; it exits non-zero when the match failed.
  status=$(hlvs submit --team-config "$team_config" --wait --poll 2)
  id=$(printf '%s' "$status" | python3 -c 'import json, sys; print(json.load(sys.stdin)["id"])')
  hlvs results "$id" --out "runs/$id" >/dev/null
  hlvs logs fetch "$id" --out "runs/$id/logs" >/dev/null
  # report.json says whose side a failure was on: discard runs with backend_error true.
  python3 - "runs/$id/report.json" <<'PY'
import json, sys
report = json.load(open(sys.argv[1]))
print(f"{report['submission']}: {report['status']}, backend_error={report['backend_error']}, "
      f"user_returncode={report['user_returncode']}")
PY
  # Your processing goes here (update parameters, push a new image, ...).
  echo "round $round of $rounds done: runs/$id"
done
