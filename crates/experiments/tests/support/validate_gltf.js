// Validates a glTF asset with the Khronos glTF validator (npm package gltf-validator): prints
// the issue counts and messages as JSON, exits 1 on any error. Usage: node validate_gltf.js FILE
// (with NODE_PATH pointing at the node_modules holding gltf-validator).
const validator = require('gltf-validator');
const fs = require('fs'); const path = require('path');
const file = process.argv[2];
validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
  uri: file,
  externalResourceFunction: (uri) => new Promise((resolve, reject) => {
    fs.readFile(path.join(path.dirname(file), decodeURIComponent(uri)), (err, data) => err ? reject(err.toString()) : resolve(new Uint8Array(data)));
  }),
}).then((r) => { console.log(JSON.stringify({errors: r.issues.numErrors, warnings: r.issues.numWarnings, infos: r.issues.numInfos, hints: r.issues.numHints, messages: r.issues.messages.map(m => `${m.severity} ${m.code} ${m.pointer||''} ${m.message}`)}, null, 1)); process.exit(r.issues.numErrors > 0 ? 1 : 0); })
 .catch((e) => { console.error(e); process.exit(2); });
