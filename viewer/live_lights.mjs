// The standard mode's live lights (viewer/index.html): the bake's lights (the glb's scene extras.microshadow.lights,
// in world coordinates, radiance in the scene's units) as three.js lights whose unshadowed direct light equals
// microshadow's, and the standard materials patched so that each light's direct contribution is multiplied by its
// shadowmask channel sampled at TEXCOORD_1 (what Unity's and Godot's shadowmask modes do with their real-time
// lights). three.js's lights are physical (r155+: no legacy units), and every light is scaled by the exposure.
//
// Units, per light of radiance L (microshadow: every shape emits as a one-sided Lambertian surface, and a
// Lambertian receiver of albedo a shows a E S / pi, E the unshadowed irradiance; docs/design.md, "Units"):
// - rect: RectAreaLight of intensity L. three.js shades it with LTC: diffuse = colour x diffuseColor x F, F the
//   rectangle's form factor clipped to the receiver's horizon (exactly, with exactLtcPars below), i.e. E / (pi L);
//   so its diffuse radiance is a x L x E / (pi L) = a E / pi, microshadow's. (three.js calls the intensity luminance in nits: power = intensity x pi x area, as
//   microshadow's flux = pi A L.) A parallelogram is kept: the light's matrix carries the two edge directions,
//   which three.js turns into its half-width and half-height vectors without making them orthogonal.
// - disk: no disk light in three.js; a RectAreaLight square of the disk's area (side r sqrt(pi)), centre and
//   normal: the same power, and the same irradiance far from it; near it the corners depart from the circle.
// - triangle: the parallelogram of half its edges' lengths (edges / sqrt 2) centred on the triangle's centroid:
//   equal area, orientation and centroid, so again the same power and the same far field.
// - sphere: PointLight (decay 2, no cut-off) of intensity pi r^2 L at the centre: its irradiance I cos / d^2 is
//   the sphere's pi L (r/d)^2 cos wherever the sphere is wholly above the horizon; the highlight is a point's.
// - sun: DirectionalLight of intensity pi L sin^2(alpha), the cone's irradiance at normal incidence (three.js's
//   directional irradiance is intensity x cos); no penumbra in the highlight.
import * as THREE from 'three';
import { RectAreaLightUniformsLib } from 'three/addons/lights/RectAreaLightUniformsLib.js';

const v3 = (a) => new THREE.Vector3().fromArray(a);

// A RectAreaLight on the parallelogram centre +- hs/2 +- ht/2 of edge vectors hs, ht, emitting towards cross(hs, ht)
// (three.js's emits towards local -z, with local x = width, y = height: x along ht, y along hs makes -z that side).
function parallelogramLight(colour, centre, hs, ht) {
  const light = new THREE.RectAreaLight(colour, 1, ht.length(), hs.length());
  const n = new THREE.Vector3().crossVectors(hs, ht).normalize();
  light.matrixAutoUpdate = false;
  light.matrix.makeBasis(ht.clone().normalize(), hs.clone().normalize(), n.negate()).setPosition(centre);
  light.matrixWorldNeedsUpdate = true;
  return light;
}

// The three.js light of one light of the glb and its kind ('rect', 'point', 'dir': the uniform array it lands
// in), or null with the reason for a shape this viewer does not know.
function makeLight(def, exposure) {
  const L = new THREE.Color().setRGB(...def.radiance.map((x) => x * exposure), THREE.LinearSRGBColorSpace);
  if (def.shape === 'rect' || def.shape === 'disk' || def.shape === 'triangle') {
    const c = v3(def.corner), es = v3(def.edge_s), et = v3(def.edge_t);
    if (def.shape === 'rect') return { kind: 'rect', light: parallelogramLight(L, c.addScaledVector(es, 0.5).addScaledVector(et, 0.5), es, et) };
    if (def.shape === 'disk') {   // the bounding square of the disk (ms_light_disk): radius |edge_s| / 2
      const side = 0.5 * es.length() * Math.sqrt(Math.PI);
      return { kind: 'rect', light: parallelogramLight(L, c.addScaledVector(es, 0.5).addScaledVector(et, 0.5),
                                                       es.clone().setLength(side), et.clone().setLength(side)),
               note: 'as a square of its area' };
    }
    return { kind: 'rect', light: parallelogramLight(L, c.addScaledVector(es, 1 / 3).addScaledVector(et, 1 / 3),
                                                     es.clone().multiplyScalar(Math.SQRT1_2), et.clone().multiplyScalar(Math.SQRT1_2)),
             note: 'as a parallelogram of its area' };
  }
  if (def.shape === 'sphere') {
    const light = new THREE.PointLight(L.multiplyScalar(Math.PI * def.radius * def.radius), 1, 0, 2);
    light.position.fromArray(def.center);
    return { kind: 'point', light, note: 'as a point of its intensity' };
  }
  if (def.shape === 'sun') {
    const s = Math.sin(def.angular_diameter_deg * Math.PI / 360);
    const light = new THREE.DirectionalLight(L.multiplyScalar(Math.PI * s * s), 1);
    light.position.fromArray(def.direction);   // the target stays at the origin: direction = position - target
    return { kind: 'dir', light, note: 'as a directional light' };
  }
  return null;
}

// The live lights of the glb's light list `defs`: { lights: [{ index, shape, kind, slot, light, note }], unknown:
// [indices] }, slot the light's place in its kind's uniform array (three.js fills each array in the order the scene
// lists the lights: none casts a shadow or carries a map, so its sort keeps that order). Each light and, for
// directional ones, its target are added to `world` in that order.
export function liveLights(defs, exposure, world) {
  RectAreaLightUniformsLib.init();
  const out = { lights: [], unknown: [] }, slots = { rect: 0, point: 0, dir: 0 };
  defs.forEach((def, index) => {
    const made = makeLight(def, exposure);
    if (!made) { out.unknown.push(index); return; }
    world.add(made.light);
    if (made.light.isDirectionalLight) world.add(made.light.target);
    out.lights.push({ index, shape: def.shape, kind: made.kind, slot: slots[made.kind]++, light: made.light, note: made.note });
  });
  out.counts = slots;
  return out;
}

// The mask of one light at a fragment: one + dot(sel, shadowmask texel); sel picks the light's channel (one = 0),
// or sel = 0, one = 1 for a light without a channel (unshadowed).
const fragmentDecl = `
uniform sampler2D msShadowmask;
varying vec2 vMsUv1;
#if NUM_RECT_AREA_LIGHTS > 0
uniform vec4 msSelRect[ NUM_RECT_AREA_LIGHTS ];
uniform float msOneRect[ NUM_RECT_AREA_LIGHTS ];
#endif
#if NUM_POINT_LIGHTS > 0
uniform vec4 msSelPoint[ NUM_POINT_LIGHTS ];
uniform float msOnePoint[ NUM_POINT_LIGHTS ];
#endif
#if NUM_DIR_LIGHTS > 0
uniform vec4 msSelDir[ NUM_DIR_LIGHTS ];
uniform float msOneDir[ NUM_DIR_LIGHTS ];
#endif
float msMask( const in vec4 sel, const in float one ) { return one + dot( sel, texture2D( msShadowmask, vMsUv1 ) ); }
`;

// lights_fragment_begin with each light's colour multiplied by its mask before its contribution is added: in the
// point and directional loops after the light's info (so before RE_Direct, diffuse and specular alike), in the
// RectAreaLight loop on the light's copy before RE_Direct_RectArea.
function maskedLightsChunk() {
  let chunk = THREE.ShaderChunk.lights_fragment_begin;
  const steps = [
    ['getPointLightInfo( pointLight, geometryPosition, directLight );', 'directLight.color *= msMask( msSelPoint[ i ], msOnePoint[ i ] );'],
    ['getDirectionalLightInfo( directionalLight, directLight );', 'directLight.color *= msMask( msSelDir[ i ], msOneDir[ i ] );'],
    ['rectAreaLight = rectAreaLights[ i ];', 'rectAreaLight.color *= msMask( msSelRect[ i ], msOneRect[ i ] );'],
  ];
  for (const [at, add] of steps) {
    if (!chunk.includes(at)) throw new Error(`three.js's lights_fragment_begin has no "${at}": the shadowmask patch needs updating`);
    chunk = chunk.replace(at, `${at}\n\t\t${add}`);
  }
  return chunk;
}

// LTC_Evaluate with the polygon clipped to the receiver's horizon exactly (Heitz et al. 2016, as microshadow's
// irradiance and its LTC specular clip it) in place of three.js's approximation of a clipped polygon by a sphere
// of the same vector form factor, which departs wherever a large, near light straddles the horizon (curved
// receivers under it). The clipped polygon has at most 5 vertices.
const exactClip = `
	vec3 clipped[ 5 ];
	int nc = 0;
	for ( int k = 0; k < 4; k ++ ) {
		vec3 a = coords[ k ], b = coords[ ( k + 1 ) % 4 ];
		if ( a.z > 0.0 ) { clipped[ nc ] = a; nc ++; }
		if ( ( a.z > 0.0 ) != ( b.z > 0.0 ) ) { clipped[ nc ] = mix( a, b, a.z / ( a.z - b.z ) ); nc ++; }
	}
	vec3 vectorFormFactor = vec3( 0.0 );
	for ( int k = 0; k < 5; k ++ ) {
		if ( k >= nc ) break;
		vectorFormFactor += LTC_EdgeVectorFormFactor( normalize( clipped[ k ] ), normalize( clipped[ ( k + 1 ) % nc ] ) );
	}
	float result = max( vectorFormFactor.z, 0.0 );`;

function exactLtcPars() {
  const chunk = THREE.ShaderChunk.lights_physical_pars_fragment;
  const from = 'coords[ 0 ] = normalize( coords[ 0 ] );', to = 'float result = LTC_ClippedSphereFormFactor( vectorFormFactor );';
  const a = chunk.indexOf(from), b = chunk.indexOf(to);
  if (a < 0 || b < a) throw new Error("three.js's LTC_Evaluate has changed: the horizon clipping patch needs updating");
  return chunk.slice(0, a) + exactClip.trim() + chunk.slice(b + to.length);
}

let white = null;

// Patches material m (a MeshStandardMaterial of the glb) to shadow the live lights by its shadowmask texture `mask`
// (null: none; every light unshadowed) whose channels are `channels` (the material's extras.shadowmask.channels:
// [{channel: 'R', light: 0}, ...]). Returns the glb light indices that found no channel. The shader text is the
// same for every material (its program is shared); the uniforms are the material's own.
export function shadowmaskMaterial(m, mask, channels, live) {
  white ??= Object.assign(new THREE.DataTexture(new Uint8Array([255, 255, 255, 255]), 1, 1), { needsUpdate: true });
  const channelOf = new Map((mask ? channels ?? [] : []).map((c) => [c.light, 'RGBA'.indexOf(c.channel)]));
  const sel = { rect: [], point: [], dir: [] }, one = { rect: [], point: [], dir: [] }, missing = [];
  for (const l of live.lights) {
    const ch = channelOf.get(l.index) ?? -1;
    const s = new THREE.Vector4(0, 0, 0, 0);   // (three.js's default w is 1)
    if (ch >= 0) s.setComponent(ch, 1); else missing.push(l.index);
    sel[l.kind][l.slot] = s;
    one[l.kind][l.slot] = ch >= 0 ? 0 : 1;
  }
  const uniforms = {
    msShadowmask: { value: mask ?? white },
    msSelRect: { value: sel.rect }, msOneRect: { value: one.rect },
    msSelPoint: { value: sel.point }, msOnePoint: { value: one.point },
    msSelDir: { value: sel.dir }, msOneDir: { value: one.dir },
  };
  m.onBeforeCompile = (shader) => {
    Object.assign(shader.uniforms, uniforms);
    shader.vertexShader = shader.vertexShader
      .replace('#include <common>', '#include <common>\n#ifndef USE_UV1\nattribute vec2 uv1;\n#endif\nvarying vec2 vMsUv1;')
      .replace('#include <uv_vertex>', '#include <uv_vertex>\nvMsUv1 = uv1;');
    shader.fragmentShader = shader.fragmentShader
      .replace('#include <common>', `#include <common>\n${fragmentDecl}`)
      .replace('#include <lights_physical_pars_fragment>', exactLtcPars())
      .replace('#include <lights_fragment_begin>', maskedLightsChunk());
  };
  m.customProgramCacheKey = () => 'microshadow-shadowmask';
  m.needsUpdate = true;
  return missing;
}
