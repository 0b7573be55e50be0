// Glossy (view-dependent) light of trilux bakes, evaluated for the eye.
//
// A glossy side of a bake carries, per vertex, the nine order-2 real
// spherical-harmonic coefficients of its glossy outgoing radiance in world
// coordinates, RGB each, as the application attributes _TRILUX_SH0 ..
// _TRILUX_SH8 (three.js names them _trilux_sh0 ..; docs/bake.md). The
// coefficients are interpolated across each triangle and the expansion is
// evaluated per pixel towards the eye, L_g = max(0, Σ_j c_j Y_j(ω_o)) with
// ω_o the unit vector from the point to the camera, and added to the
// diffuse colour (vertex colour × albedo map) before tone mapping.
// One uniform switches it off (diffuse only).

export const SH_COEFFICIENTS = 9;

const names = Array.from({ length: SH_COEFFICIENTS }, (_, j) => `_trilux_sh${j}`);

// The Y_j of docs/bake.md (and trilux_bake::directional::sh_basis).
const FRAGMENT_SH = `
uniform float triluxGlossy;
${names.map((_, j) => `varying vec3 vTriluxSh${j};`).join('\n')}
varying vec3 vTriluxWorld;
vec3 triluxGlossyLight(vec3 d) {
	vec3 l = 0.2820947917738781 * vTriluxSh0
		+ 0.4886025119029199 * (d.y * vTriluxSh1 + d.z * vTriluxSh2 + d.x * vTriluxSh3)
		+ 1.0925484305920792 * (d.x * d.y * vTriluxSh4 + d.y * d.z * vTriluxSh5 + d.x * d.z * vTriluxSh7)
		+ 0.3153915652525200 * (3.0 * d.z * d.z - 1.0) * vTriluxSh6
		+ 0.5462742152960396 * (d.x * d.x - d.y * d.y) * vTriluxSh8;
	return max(l, vec3(0.0));
}
`;

const VERTEX_SH = `
${names.map((n, j) => `attribute vec3 ${n};\nvarying vec3 vTriluxSh${j};`).join('\n')}
varying vec3 vTriluxWorld;
`;

// True when the geometry carries all nine coefficient attributes.
export function hasGlossyAttributes(geometry) {
	return names.every((n) => geometry.attributes[n] && geometry.attributes[n].itemSize === 3);
}

// Makes `material` (a clone is returned) add the glossy light; `uniform`
// is the shared { value } that scales it (1 on, 0 diffuse only).
function glossyMaterial(material, uniform) {
	const m = material.clone();
	m.onBeforeCompile = (shader) => {
		shader.uniforms.triluxGlossy = uniform;
		shader.vertexShader = shader.vertexShader
			.replace('#include <common>', `#include <common>\n${VERTEX_SH}`)
			.replace('#include <project_vertex>', `#include <project_vertex>
	vTriluxWorld = (modelMatrix * vec4(transformed, 1.0)).xyz;
${names.map((n, j) => `	vTriluxSh${j} = ${n};`).join('\n')}`);
		shader.fragmentShader = shader.fragmentShader
			.replace('#include <common>', `#include <common>\n${FRAGMENT_SH}`)
			.replace('#include <color_fragment>', `#include <color_fragment>
	diffuseColor.rgb += triluxGlossy * triluxGlossyLight(normalize(cameraPosition - vTriluxWorld));`);
	};
	m.customProgramCacheKey = () => 'trilux-glossy-sh2';
	m.userData = { ...material.userData, triluxGlossy: true };
	return m;
}

// Gives every mesh under `root` whose geometry has the coefficients a
// glossy material; returns how many meshes.
export function useGlossyAttributes(root, uniform) {
	let n = 0;
	root.traverse((obj) => {
		if (!obj.isMesh || !hasGlossyAttributes(obj.geometry)) return;
		obj.material = Array.isArray(obj.material)
			? obj.material.map((m) => glossyMaterial(m, uniform))
			: glossyMaterial(obj.material, uniform);
		n++;
	});
	return n;
}
