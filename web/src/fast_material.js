// A lit material for software GL (SwiftShader, llvmpipe): the light is computed per vertex
// (ambient + two directional lights, Lambert), so the fragment shader only interpolates and
// multiplies. On a CPU rasterizer the fragments are the cost: three's MeshStandardMaterial
// draws the cabinet at about a quarter of this material's frame rate there.
import * as THREE from 'three';

// world-space directions towards the lights, and their colours (linear)
export const LIGHTS = {
  ambient: new THREE.Color(0.42, 0.42, 0.44),
  key: { dir: new THREE.Vector3(2, 1.2, 3).normalize(), color: new THREE.Color(0.72, 0.72, 0.7) },
  fill: { dir: new THREE.Vector3(-2, -1.5, 1).normalize(), color: new THREE.Color(0.22, 0.22, 0.24) },
};

const vertexShader = /* glsl */ `
uniform vec3 uAmbient;
uniform vec3 uKeyDir;
uniform vec3 uKeyColor;
uniform vec3 uFillDir;
uniform vec3 uFillColor;
varying vec3 vLight;
varying vec2 vUv;
void main() {
  vec3 n = normalize(transpose(inverse(mat3(modelMatrix))) * normal);
  vLight = uAmbient + uKeyColor * max(dot(n, uKeyDir), 0.0) + uFillColor * max(dot(n, uFillDir), 0.0);
  vUv = uv;
  gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0);
}`;

const fragmentShader = /* glsl */ `
uniform vec3 uColor;
uniform vec3 uEmissive;
uniform float uOpacity;
uniform bool uHasMap;
uniform sampler2D uMap;
varying vec3 vLight;
varying vec2 vUv;
void main() {
  vec3 base = uColor;
  if (uHasMap) base *= texture2D(uMap, vUv).rgb;
  gl_FragColor = vec4(base * vLight + uEmissive, uOpacity);
  #include <colorspace_fragment>
}`;

/** A ShaderMaterial with `color` and `emissive` (THREE.Color) as MeshStandardMaterial has. */
export function makeFastMaterial(color, opacity, map) {
  const m = new THREE.ShaderMaterial({
    uniforms: {
      uColor: { value: color.clone() },
      uEmissive: { value: new THREE.Color(0, 0, 0) },
      uOpacity: { value: opacity },
      uHasMap: { value: !!map },
      uMap: { value: map || null },
      uAmbient: { value: LIGHTS.ambient },
      uKeyDir: { value: LIGHTS.key.dir },
      uKeyColor: { value: LIGHTS.key.color },
      uFillDir: { value: LIGHTS.fill.dir },
      uFillColor: { value: LIGHTS.fill.color },
    },
    vertexShader,
    fragmentShader,
    transparent: opacity < 1,
  });
  m.color = m.uniforms.uColor.value;
  m.emissive = m.uniforms.uEmissive.value;
  return m;
}
