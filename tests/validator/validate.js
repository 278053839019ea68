// Runs the Khronos glTF-Validator (npm gltf-validator, installed here by
// scripts/install-deps.sh) on each file given and prints one line per file:
//   <file>: <E> errors, <W> warnings, <I> infos, <H> hints
// followed by each error (code, pointer, message). Exit status 1 when a file
// has an error or cannot be read, 2 when the validator is not installed.
'use strict';
const fs = require('fs');
const path = require('path');

let validator;
try {
    validator = require(path.join(__dirname, 'node_modules', 'gltf-validator'));
} catch (e) {
    console.error('gltf-validator is not installed in ' + __dirname + ' (run scripts/install-deps.sh)');
    process.exit(2);
}

async function validate(file) {
    const bytes = new Uint8Array(fs.readFileSync(file));
    const report = await validator.validateBytes(bytes, {
        uri: path.basename(file),
        maxIssues: 0,
        externalResourceFunction: (uri) =>
            new Promise((resolve, reject) => {
                fs.readFile(path.join(path.dirname(file), decodeURIComponent(uri)), (err, data) =>
                    err ? reject(err.toString()) : resolve(new Uint8Array(data)));
            }),
    });
    const i = report.issues;
    console.log(`${file}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos, ${i.numHints} hints` +
                ` (gltf-validator ${report.validatorVersion})`);
    for (const m of i.messages) {
        if (m.severity === 0) console.log(`  error ${m.code} at ${m.pointer || '-'}: ${m.message}`);
    }
    if (process.env.GLTF_VALIDATOR_VERBOSE) {
        for (const m of i.messages) {
            if (m.severity !== 0) console.log(`  severity ${m.severity} ${m.code} at ${m.pointer || '-'}: ${m.message}`);
        }
    }
    return i.numErrors;
}

(async () => {
    const files = process.argv.slice(2);
    if (files.length === 0) {
        console.error('usage: node validate.js FILE.glb...');
        process.exit(2);
    }
    let failed = false;
    for (const f of files) {
        try {
            if ((await validate(f)) > 0) failed = true;
        } catch (e) {
            console.log(`${f}: cannot be validated: ${e}`);
            failed = true;
        }
    }
    process.exit(failed ? 1 : 0);
})();
