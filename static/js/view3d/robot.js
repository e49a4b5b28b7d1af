// The robot's model: the URDF text from GET /api/3d/robot built by urdf-loader, its meshes fetched from
// /api/3d/mesh/<package>/<path> only (a file:// or relative mesh is refused and counted). Each link is
// then placed from TF on its own, as RViz's RobotModel does: the links are lifted out of urdf-loader's
// joint tree, and a link TF does not know keeps its pose from the URDF (zero joints) under the root.
import * as THREE from './three.js';
import { at } from '../core/api.js';
import { _ } from '../core/i18n.js';

const MESH_LOADERS = {
  stl: (url, manager, material, done) => new THREE.STLLoader(manager).load(url,
    (geometry) => done(new THREE.Mesh(geometry, material || new THREE.MeshPhongMaterial())), null,
    (err) => done(null, err)),
  dae: (url, manager, _material, done) => new THREE.ColladaLoader(manager).load(url,
    (dae) => done(dae.scene), null, (err) => done(null, err)),
  obj: (url, manager, material, done) => new THREE.OBJLoader(manager).load(url, (group) => {
    if (material) group.traverse((child) => { if (child.isMesh) child.material = material; });
    done(group);
  }, null, (err) => done(null, err)),
};

export class RobotModel {
  constructor(parent) {
    this.group = new THREE.Group();
    this.group.name = 'robot';
    parent.add(this.group);
    this.links = new Map();      // name -> Object3D placed directly under the group
    this.defaults = new Map();   // name -> its pose under the root at zero joints
    this.root = null;
    this.meshErrors = [];
    this.pending = 0;
  }

  clear() {
    for (const link of this.links.values()) this.group.remove(link);
    this.links.clear();
    this.defaults.clear();
    this.meshErrors = [];
  }

  // Build from the description; resolves when every mesh has loaded or failed.
  build(description) {
    this.clear();
    this.root = description.root;
    const meshBase = at('/api/3d/mesh');
    const manager = new THREE.LoadingManager();
    const loader = new THREE.URDFLoader(manager);
    loader.packages = (pkg) => `${meshBase}/${encodeURIComponent(pkg)}`;
    loader.loadMeshCb = (url, mgr, material, done) => {
      const kind = (url.match(/\.(\w+)$/) || [])[1]?.toLowerCase();
      if (!url.startsWith(meshBase + '/') || !MESH_LOADERS[kind]) {
        this.meshErrors.push(_('%(url)s: only package:// meshes (STL, DAE, OBJ) are drawn', { url }));
        done(null);
        return;
      }
      this.pending += 1;
      MESH_LOADERS[kind](url, mgr, material, (mesh, err) => {
        this.pending -= 1;
        if (err || !mesh) this.meshErrors.push(`${url}: ${err?.message || _('not loaded')}`);
        done(mesh, err);
      });
    };
    const done = new Promise((resolve) => {
      manager.onLoad = resolve;
      manager.onError = () => {};
    });
    const robot = loader.parse(description.urdf);
    robot.updateMatrixWorld(true);
    const rootInverse = robot.matrixWorld.clone().invert();
    for (const [name, link] of Object.entries(robot.links)) {
      this.defaults.set(name, rootInverse.clone().multiply(link.matrixWorld));
    }
    // Lift every link out of the joint tree: TF places each one, joints only gave the defaults.
    for (const [name, link] of Object.entries(robot.links)) {
      for (const child of [...link.children]) if (child.isURDFJoint) link.remove(child);
      link.removeFromParent();
      link.matrixAutoUpdate = false;
      link.matrix.copy(this.defaults.get(name));
      this.group.add(link);
      this.links.set(name, link);
    }
    return this.pending ? done : Promise.resolve();
  }

  // Place every link: from TF where it knows the link, else its URDF pose under the root.
  place(poses) {
    const fixedInverse = poses.fixedInverse();
    const rootPose = poses.inFixed(this.root || poses.base, fixedInverse);
    let placed = 0;
    for (const [name, link] of this.links) {
      const fromTf = poses.inFixed(name, fixedInverse);
      if (fromTf) {
        link.matrix.copy(fromTf);
        placed += 1;
      } else if (rootPose) {
        link.matrix.copy(rootPose.clone().multiply(this.defaults.get(name)));
      } else {
        link.matrix.copy(this.defaults.get(name));
      }
      link.matrixWorldNeedsUpdate = true;
    }
    return placed;
  }

  // The root link's position in the fixed frame (follow, top-down).
  rootPosition() {
    const link = this.links.get(this.root);
    return link ? new THREE.Vector3().setFromMatrixPosition(link.matrix) : new THREE.Vector3();
  }
}
