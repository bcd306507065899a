#!/usr/bin/env bash
# Makes sure a PostgreSQL server answers on 127.0.0.1 for the service's tests (Debian's server,
# installed by setup-system.sh) and writes its URL to /var/lib/hlvs/postgres-test-url.
# Without root or without Debian's PostgreSQL tools it does nothing: those tests then skip.
set -euo pipefail
URL_FILE=/var/lib/hlvs/postgres-test-url
if [ "$(id -u)" != 0 ] || ! command -v pg_lsclusters >/dev/null; then
  echo "==> PostgreSQL tests skipped (needs root and Debian's postgresql package)"
  exit 0
fi
mkdir -p /var/lib/hlvs /var/log/hlvs
version=$(pg_lsclusters -h | awk 'NR==1 {print $1}')
if [ -z "$version" ]; then
  version=$(ls /usr/lib/postgresql | sort -n | tail -1)
  pg_createcluster "$version" main >>/var/log/hlvs/postgres.log 2>&1
fi
cluster=$(pg_lsclusters -h | awk -v v="$version" '$1==v {print $2; exit}')
port=$(pg_lsclusters -h | awk -v v="$version" '$1==v {print $3; exit}')
if ! pg_lsclusters -h | awk -v v="$version" -v c="$cluster" '$1==v && $2==c {print $4}' | grep -q online; then
  echo "==> starting PostgreSQL $version/$cluster on 127.0.0.1:$port"
  pg_ctlcluster "$version" "$cluster" start >>/var/log/hlvs/postgres.log 2>&1 || {
    echo "hlvs setup: PostgreSQL did not start; see /var/log/hlvs/postgres.log" >&2; exit 1; }
fi
for _ in $(seq 1 60); do
  runuser -u postgres -- psql -p "$port" -tAc 'SELECT 1' >/dev/null 2>&1 && break
  sleep 0.5
done
runuser -u postgres -- psql -p "$port" -v ON_ERROR_STOP=1 -q >/dev/null <<'SQL'
DO $$ BEGIN
  IF NOT EXISTS (SELECT FROM pg_roles WHERE rolname = 'hlvs_test') THEN
    CREATE ROLE hlvs_test LOGIN CREATEDB PASSWORD 'hlvs_test';
  END IF;
END $$;
SQL
echo "postgresql+psycopg://hlvs_test:hlvs_test@127.0.0.1:$port/postgres" > "$URL_FILE"
echo "==> PostgreSQL ready for tests on 127.0.0.1:$port"
