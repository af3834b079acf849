#!/usr/bin/env node
// Validates a .gltf or .glb with the Khronos glTF validator (npm gltf-validator,
// installed in tests/tools/node_modules by scripts/test.sh) and prints its
// report's issue counts and messages as JSON for tests/writers_external.rs.
// External resources (a .gltf's .bin) are read relative to the file.
// Exit 3 when the validator is not installed.
'use strict';
const fs = require('fs');
const path = require('path');

let validator;
try {
  validator = require('gltf-validator');
} catch (e) {
  console.error(`gltf-validator is not installed: ${e.message}`);
  process.exit(3);
}

const file = process.argv[2];
if (!file) {
  console.error('usage: validate_gltf.js FILE.gltf|FILE.glb');
  process.exit(2);
}
const folder = path.dirname(file);
validator
  .validateBytes(new Uint8Array(fs.readFileSync(file)), {
    uri: path.basename(file),
    maxIssues: 100,
    externalResourceFunction: (uri) =>
      new Promise((resolve, reject) => {
        fs.readFile(path.join(folder, decodeURIComponent(uri)), (err, data) =>
          err ? reject(err.toString()) : resolve(new Uint8Array(data)));
      }),
  })
  .then((report) => {
    const issues = report.issues;
    console.log(JSON.stringify({
      numErrors: issues.numErrors,
      numWarnings: issues.numWarnings,
      numInfos: issues.numInfos,
      numHints: issues.numHints,
      messages: issues.messages.map((m) => `${m.severity} ${m.code} ${m.pointer || ''}: ${m.message}`),
      info: report.info ? {
        drawCallCount: report.info.drawCallCount,
        totalVertexCount: report.info.totalVertexCount,
        totalTriangleCount: report.info.totalTriangleCount,
      } : null,
    }));
  })
  .catch((e) => {
    console.error(`validation failed: ${e}`);
    process.exit(1);
  });
