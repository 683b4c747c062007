// Loads wind GLBs with three.js's own GLTFLoader under Node, plays their `wind` clip with an
// AnimationMixer and checks that the joints move, that the clip loops, and that the skinned
// mesh is bound to them. Usage: node tools/three-check/wind.mjs FILE.glb...
// three.js comes from the studio's pinned install: npm ci --prefix crates/sylva-studio/web
import fs from "node:fs";
import path from "node:path";
import { fileURLToPath, pathToFileURL } from "node:url";

const here = path.dirname(fileURLToPath(import.meta.url));
const three = path.resolve(here, "../../crates/sylva-studio/web/node_modules/three");
if (!fs.existsSync(path.join(three, "build/three.module.js"))) {
  console.error("three.js is not installed: run `npm ci --prefix crates/sylva-studio/web`");
  process.exit(2);
}
const THREE = await import(pathToFileURL(path.join(three, "build/three.module.js")).href);
const { GLTFLoader } = await import(pathToFileURL(path.join(three, "examples/jsm/loaders/GLTFLoader.js")).href);

// GLTFLoader reads `self.URL`, as in a browser. Textures need a DOM to decode; geometry,
// skins and clips do not: their failures are left unsaid.
globalThis.self = globalThis;
const quiet = console.error;
console.error = (...a) => (String(a[0]).includes("Couldn't load texture") ? undefined : quiet(...a));

let failed = false;
for (const file of process.argv.slice(2)) {
  const bytes = fs.readFileSync(file);
  const data = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
  const gltf = await new Promise((resolve, reject) => new GLTFLoader().parse(data, "", resolve, reject));
  const clip = gltf.animations.find((a) => a.name === "wind");
  const problems = [];
  if (!clip) problems.push("no clip named wind");
  let skinned = 0;
  let bones = 0;
  gltf.scene.traverse((o) => {
    if (o.isSkinnedMesh) {
      skinned += 1;
      bones = Math.max(bones, o.skeleton.bones.length);
    }
  });
  if (skinned === 0) problems.push("no skinned mesh");
  let moved = 0;
  let loopGap = 0;
  if (clip) {
    const mixer = new THREE.AnimationMixer(gltf.scene);
    mixer.clipAction(clip).play();
    const joints = clip.tracks.map((t) => gltf.scene.getObjectByName(t.name.split(".")[0]));
    const pose = () => joints.map((j) => j.quaternion.clone());
    mixer.setTime(0);
    const start = pose();
    mixer.setTime(clip.duration * 0.37);
    const later = pose();
    moved = later.filter((q, i) => q.angleTo(start[i]) > 1e-4).length;
    mixer.setTime(clip.duration);
    const end = pose();
    loopGap = Math.max(...end.map((q, i) => q.angleTo(start[i])));
    if (moved === 0) problems.push("no joint rotates when the mixer advances");
    if (loopGap > 1e-5) problems.push(`the loop jumps by ${loopGap} rad`);
  }
  const summary = `${file}: ${skinned} skinned mesh(es), ${bones} bones, clip ${clip ? clip.duration.toFixed(2) + " s, " + clip.tracks.length + " tracks" : "missing"}, ${moved} joints moved`;
  if (problems.length) {
    failed = true;
    console.log(`${summary}: FAILED: ${problems.join("; ")}`);
  } else {
    console.log(`${summary}: ok`);
  }
}
process.exit(failed ? 1 : 0);
