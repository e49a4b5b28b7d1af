// Text drawn into a canvas texture on a sprite (frame names, TEXT markers): no DOM per label, no styles.
import * as THREE from './three.js';

export function textSprite(text, { height = 0.15, color = '#ffffff' } = {}) {
  const canvas = document.createElement('canvas');
  const ctx = canvas.getContext('2d');
  const px = 48;
  ctx.font = `${px}px sans-serif`;
  canvas.width = Math.max(8, Math.ceil(ctx.measureText(text).width) + 8);
  canvas.height = px + 12;
  ctx.font = `${px}px sans-serif`;
  ctx.fillStyle = color;
  ctx.textBaseline = 'middle';
  ctx.fillText(text, 4, canvas.height / 2);
  const texture = new THREE.CanvasTexture(canvas);
  const sprite = new THREE.Sprite(new THREE.SpriteMaterial({ map: texture, depthTest: false, transparent: true }));
  sprite.scale.set(height * canvas.width / canvas.height, height, 1);
  sprite.renderOrder = 10;
  return sprite;
}

export function disposeTree(object) {
  object.traverse((child) => {
    child.geometry?.dispose?.();
    const materials = Array.isArray(child.material) ? child.material : [child.material];
    for (const m of materials) { m?.map?.dispose?.(); m?.dispose?.(); }
  });
}
