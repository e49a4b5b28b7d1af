// The vendored three.js and its addons, from one place, so a version bump changes one file.
export * from '../../vendor/three-0.187.0/three.module.min.js';
export { OrbitControls } from '../../vendor/three-0.187.0/addons/controls/OrbitControls.min.js';
export { STLLoader } from '../../vendor/three-0.187.0/addons/loaders/STLLoader.min.js';
export { OBJLoader } from '../../vendor/three-0.187.0/addons/loaders/OBJLoader.min.js';
export { ColladaLoader } from '../../vendor/three-0.187.0/addons/loaders/ColladaLoader.min.js';
export { default as URDFLoader } from '../../vendor/urdf-loader-0.13.1/URDFLoader.min.js';
