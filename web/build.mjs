// Bundles src/main.ts into the Python package (viewer/static/app.js): one file, minified, no
// source map, no timestamps, so that the same sources and lock file give the same bytes.
import { build } from "esbuild";

await build({
  entryPoints: ["src/main.ts"],
  bundle: true,
  minify: true,
  format: "esm",
  target: "es2022",
  legalComments: "none",
  outfile: "../viewer/static/app.js",
  logLevel: "info",
});

// Swagger UI for the service's /docs, served from the package (no CDN: /docs works offline).
// The bundle's source-map comment is dropped (the map is not shipped).
import { copyFileSync, mkdirSync, readFileSync, writeFileSync } from "node:fs";

const swagger = "node_modules/swagger-ui-dist";
const target = "../viewer/static/swagger";
mkdirSync(target, { recursive: true });
const bundle = readFileSync(`${swagger}/swagger-ui-bundle.js`, "utf8").replace(/\n\/\/# sourceMappingURL=.*\s*$/, "\n");
writeFileSync(`${target}/swagger-ui-bundle.js`, bundle);
for (const name of ["swagger-ui.css", "favicon-32x32.png", "LICENSE", "NOTICE", "swagger-ui-bundle.js.LICENSE.txt"]) {
  copyFileSync(`${swagger}/${name}`, `${target}/${name}`);
}
