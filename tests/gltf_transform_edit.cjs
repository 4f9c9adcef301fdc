// Edits a real model with glTF Transform's own library (@gltf-transform/core and /extensions,
// from tools/node: run with NODE_PATH=tools/node/node_modules), so the files the tests read are
// written the way glTF Transform writes them. One job per call:
//   scatter IN OUT N          the first mesh placed on N nodes (turned, scaled), nothing else
//   variants IN OUT           two variants ("red": a plain red material, "metal": the model's
//                             textured material made metal and smooth) on every primitive
//   variant-control IN OUT V  the same file with V's material set on the primitives directly
//   hide IN OUT I             node I (and so its children) marked KHR_node_visibility visible false
//   drop IN OUT I             node I removed (hide's control)
//   xmp IN OUT                KHR_xmp_json_ld packets on the asset, a node, a mesh and a material
//   copy IN OUT               read and written back unchanged (the controls' writer)
const { NodeIO } = require("@gltf-transform/core");
const { ALL_EXTENSIONS, KHRMaterialsVariants, KHRNodeVisibility, KHRXMP } = require("@gltf-transform/extensions");

function quat(axis, angle) {
  const n = Math.hypot(...axis), s = Math.sin(angle / 2) / n;
  return [axis[0] * s, axis[1] * s, axis[2] * s, Math.cos(angle / 2)];
}

function scatter(doc, count) {
  const root = doc.getRoot();
  const mesh = root.listMeshes()[0];
  for (const node of root.listNodes()) node.dispose();
  const scene = root.listScenes()[0] || doc.createScene();
  const min = mesh.listPrimitives()[0].getAttribute("POSITION").getMin([]);
  const max = mesh.listPrimitives()[0].getAttribute("POSITION").getMax([]);
  const size = Math.max(max[0] - min[0], max[1] - min[1], max[2] - min[2]);
  const columns = Math.ceil(Math.sqrt(count));
  for (let k = 0; k < count; k++) {
    const x = (k % columns) - (columns - 1) / 2, z = Math.floor(k / columns) - (columns - 1) / 2;
    const s = 0.5 + 0.4 * ((k * 7) % 5) / 4;
    const node = doc.createNode(`copy${k}`).setMesh(mesh)
      .setTranslation([x * 1.2 * size, 0.1 * size * (k % 3), z * 1.2 * size])
      .setRotation(quat([(k % 3) - 1, 1, 0.3 * (k % 2)], 0.7 * k))
      .setScale([s, s * (1 + 0.1 * (k % 4)), s]);
    scene.addChild(node);
  }
}

function variantMaterials(doc) {
  const own = doc.getRoot().listMaterials()[0];
  const red = doc.createMaterial("red").setBaseColorFactor([0.8, 0.1, 0.1, 1]).setMetallicFactor(0)
    .setRoughnessFactor(0.4);
  const metal = own.clone().setName("metal").setMetallicFactor(1).setRoughnessFactor(0.25);
  return { red, metal };
}

function variants(doc) {
  const ext = doc.createExtension(KHRMaterialsVariants);
  const materials = variantMaterials(doc);
  const mappingList = () => {
    const list = ext.createMappingList();
    for (const name of ["red", "metal"]) {
      list.addMapping(ext.createMapping().addVariant(ext.createVariant(name)).setMaterial(materials[name]));
    }
    return list;
  };
  for (const mesh of doc.getRoot().listMeshes()) {
    for (const prim of mesh.listPrimitives()) prim.setExtension("KHR_materials_variants", mappingList());
  }
}

function variantControl(doc, name) {
  const material = variantMaterials(doc)[name];
  for (const mesh of doc.getRoot().listMeshes()) {
    for (const prim of mesh.listPrimitives()) prim.setMaterial(material);
  }
}

function xmp(doc) {
  const ext = doc.createExtension(KHRXMP);
  const packet = (title) => ext.createPacket()
    .setContext({ dc: "http://purl.org/dc/elements/1.1/" })
    .setProperty("dc:creator", { "@list": ["alight tests"] })
    .setProperty("dc:title", { "@type": "rdf:Alt", "rdf:_1": { "@language": "en-us", "@value": title } });
  const root = doc.getRoot();
  root.setExtension("KHR_xmp_json_ld", packet("asset"));
  root.listNodes()[0].setExtension("KHR_xmp_json_ld", packet("node"));
  root.listMeshes()[0].setExtension("KHR_xmp_json_ld", packet("mesh"));
  root.listMaterials()[0].setExtension("KHR_xmp_json_ld", packet("material"));
}

(async () => {
  const [job, input, output, arg] = process.argv.slice(2);
  const io = new NodeIO().registerExtensions(ALL_EXTENSIONS);
  const doc = await io.read(input);
  if (job === "scatter") scatter(doc, Number(arg));
  else if (job === "variants") variants(doc);
  else if (job === "variant-control") variantControl(doc, arg);
  else if (job === "hide") {
    const visibility = doc.createExtension(KHRNodeVisibility).createVisibility().setVisible(false);
    doc.getRoot().listNodes()[Number(arg)].setExtension("KHR_node_visibility", visibility);
  } else if (job === "drop") doc.getRoot().listNodes()[Number(arg)].dispose();
  else if (job === "xmp") xmp(doc);
  else if (job !== "copy") throw new Error(`unknown job ${job}`);
  await io.write(output, doc);
})().catch((e) => { console.error(String(e.stack || e)); process.exit(1); });
