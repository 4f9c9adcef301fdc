// Validates glTF/GLB files with the Khronos glTF validator (npm: gltf-validator) and prints one
// JSON line per file: {"file", "errors", "warnings", "infos", "messages": [first errors]}.
// Exit status 1 if any file has errors. Looks for the package in tools/node (tools/setup.sh).
const fs = require("fs");
const path = require("path");
let validator;
try {
  validator = require(path.join(__dirname, "node", "node_modules", "gltf-validator"));
} catch (e) {
  validator = require("gltf-validator");
}

async function check(file) {
  const data = new Uint8Array(fs.readFileSync(file));
  const report = await validator.validateBytes(data, {
    uri: path.basename(file),
    maxIssues: 100,
    externalResourceFunction: (uri) =>
      new Promise((resolve, reject) => {
        fs.readFile(path.join(path.dirname(file), decodeURIComponent(uri)), (err, d) =>
          err ? reject(err.toString()) : resolve(new Uint8Array(d)));
      }),
  });
  const issues = report.issues;
  return {
    file,
    errors: issues.numErrors,
    warnings: issues.numWarnings,
    infos: issues.numInfos,
    messages: issues.messages.filter((m) => m.severity <= 1).slice(0, 10)
      .map((m) => `${m.severity === 0 ? "error" : "warning"} ${m.code} ${m.pointer || ""}: ${m.message}`),
  };
}

(async () => {
  let failed = false;
  for (const file of process.argv.slice(2)) {
    const r = await check(file);
    failed = failed || r.errors > 0;
    console.log(JSON.stringify(r));
  }
  process.exit(failed ? 1 : 0);
})().catch((e) => { console.error(String(e)); process.exit(2); });
