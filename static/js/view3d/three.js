// The vendored three.js and its addons, from one place, so a version bump changes one file.
export * from '../../vendor/three-0.187.0/three.module.js';
export { OrbitControls } from '../../vendor/three-0.187.0/addons/controls/OrbitControls.js';
export { STLLoader } from '../../vendor/three-0.187.0/addons/loaders/STLLoader.js';
export { OBJLoader } from '../../vendor/three-0.187.0/addons/loaders/OBJLoader.js';
export { ColladaLoader } from '../../vendor/three-0.187.0/addons/loaders/ColladaLoader.js';
export { default as URDFLoader } from '../../vendor/urdf-loader-0.13.1/URDFLoader.js';
