// Runs the Khronos glTF-Validator (npm package gltf-validator) on each file named on the command
// line, resolving external buffers and images beside the file. Prints one line per file with
// its error and warning counts and the codes of its errors; exits 1 when any file has errors.
//   NODE_PATH=<folder holding node_modules/gltf-validator> node scripts/gltf_validate.js FILE...
const validator = require('gltf-validator');
const fs = require('fs');
const path = require('path');

async function main(files) {
  let failed = 0;
  for (const file of files) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
      uri: file,
      maxIssues: 1000,
      externalResourceFunction: (uri) => new Promise((resolve, reject) => {
        try {
          resolve(new Uint8Array(fs.readFileSync(path.join(path.dirname(file), decodeURIComponent(uri)))));
        } catch (e) {
          reject(e.toString());
        }
      }),
    });
    const errors = report.issues.messages.filter((m) => m.severity === 0);
    const codes = [...new Set(errors.map((m) => m.code + ' at ' + m.pointer))].slice(0, 5);
    console.log(`${file}: ${report.issues.numErrors} errors, ${report.issues.numWarnings} warnings` +
                (codes.length ? ` (${codes.join(', ')})` : ''));
    if (report.issues.numErrors > 0) failed++;
  }
  process.exit(failed ? 1 : 0);
}

main(process.argv.slice(2)).catch((e) => {
  console.error(e.toString());
  process.exit(2);
});
