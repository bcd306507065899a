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
