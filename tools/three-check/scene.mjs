// Loads GLBs with three.js's own GLTFLoader under Node and prints, per file, one line of JSON
// saying what three.js made of it: the names of the scene's top nodes, the meshes, instanced
// meshes and their instance counts, the distinct geometries, the materials (name, three.js
// type, alpha test) and whether they use vertex colours, how many geometries carry a colour attribute, and the world-space box
// of every vertex (instances and quantised positions included). Tests read the lines.
// Usage: node tools/three-check/scene.mjs FILE.glb...
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
const { Box3 } = await import(pathToFileURL(path.join(three, "build/three.module.js")).href);
const { GLTFLoader } = await import(pathToFileURL(path.join(three, "examples/jsm/loaders/GLTFLoader.js")).href);

// GLTFLoader reads `self.URL`, as in a browser. Textures need a DOM to decode: their failures
// are left unsaid.
globalThis.self = globalThis;
const quiet = console.error;
console.error = (...a) => (String(a[0]).includes("Couldn't load texture") ? undefined : quiet(...a));

for (const file of process.argv.slice(2)) {
  const bytes = fs.readFileSync(file);
  const data = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
  const gltf = await new Promise((resolve, reject) => new GLTFLoader().parse(data, "", resolve, reject));
  const geometries = new Set();
  const materials = new Map();
  let meshes = 0;
  let instanced = 0;
  let instances = 0;
  let triangles = 0;
  gltf.scene.traverse((o) => {
    if (!o.isMesh) return;
    meshes += 1;
    const count = o.isInstancedMesh ? o.count : 1;
    if (o.isInstancedMesh) {
      instanced += 1;
      instances += o.count;
    }
    geometries.add(o.geometry);
    const index = o.geometry.index;
    triangles += count * (index ? index.count : o.geometry.attributes.position.count) / 3;
    for (const m of [o.material].flat()) materials.set(m.uuid, { name: m.name, type: m.type, alphaTest: m.alphaTest, vertexColors: m.vertexColors });
  });
  const colored = [...geometries].filter((g) => g.attributes.color).length;
  gltf.scene.updateMatrixWorld(true);
  const box = new Box3().setFromObject(gltf.scene, true);
  console.log(JSON.stringify({
    file,
    nodes: gltf.scene.children.map((c) => c.name),
    extras: gltf.scene.children.map((c) => Object.fromEntries(Object.entries(c.userData).filter(([k]) => k !== "genome"))),
    meshes,
    instanced,
    instances,
    geometries: geometries.size,
    colored,
    triangles,
    box: box.isEmpty() ? null : [box.min.toArray(), box.max.toArray()],
    materials: [...materials.values()],
  }));
}
