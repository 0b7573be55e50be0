// Glossy (view-dependent) light of trilux bakes, evaluated for the eye.
//
// A glossy side of a bake carries, per vertex, its glossy outgoing
// radiance in world coordinates in one of two forms (docs/bake.md):
// "sh2+lobe" (the default): order-2 real spherical harmonics _TRILUX_SH0 ..
// _TRILUX_SH8 (RGB each) plus one spherical Gaussian, _TRILUX_LOBE its
// axis times its sharpness v and _TRILUX_LOBE_RGB its amplitude a,
//   L_g = max(0, Σ_{j<9} c_j Y_j(ω_o) + a exp(v·ω_o − |v|));
// "sh2": order-2 harmonics _TRILUX_SH0 .. _TRILUX_SH8,
//   L_g = max(0, Σ_{j<9} c_j Y_j(ω_o)).
// three.js names the attributes _trilux_sh0 .., _trilux_lobe,
// _trilux_lobe_rgb. They are interpolated across each triangle and the form
// is evaluated per pixel towards the eye (ω_o the unit vector from the
// point to the camera) and added to the diffuse colour (vertex colour ×
// albedo map) before tone mapping. One uniform switches it off.

export const SH_COEFFICIENTS = 9;

const sh = (n) => Array.from({ length: n }, (_, j) => `_trilux_sh${j}`);
const FORMS = {
	lobe: [...sh(9), '_trilux_lobe', '_trilux_lobe_rgb'],
	sh2: sh(9),
};

// The Y_j of docs/bake.md (and trilux_bake::directional::sh_basis).
const ORDER2 = `0.2820947917738781 * vTrilux0
		+ 0.4886025119029199 * (d.y * vTrilux1 + d.z * vTrilux2 + d.x * vTrilux3)
		+ 1.0925484305920792 * (d.x * d.y * vTrilux4 + d.y * d.z * vTrilux5 + d.x * d.z * vTrilux7)
		+ 0.3153915652525200 * (3.0 * d.z * d.z - 1.0) * vTrilux6
		+ 0.5462742152960396 * (d.x * d.x - d.y * d.y) * vTrilux8`;
const BODY = {
	lobe: `vec3 l = ${ORDER2}
		+ vTrilux10 * exp(dot(vTrilux9, d) - length(vTrilux9));`,
	sh2: `vec3 l = ${ORDER2};`,
};

const varyings = (names) => names.map((_, j) => `varying vec3 vTrilux${j};`).join('\n');

function fragment(form) {
	return `
uniform float triluxGlossy;
${varyings(FORMS[form])}
varying vec3 vTriluxWorld;
vec3 triluxGlossyLight(vec3 d) {
	${BODY[form]}
	return max(l, vec3(0.0));
}
`;
}

function vertex(form) {
	return `
${FORMS[form].map((n) => `attribute vec3 ${n};`).join('\n')}
${varyings(FORMS[form])}
varying vec3 vTriluxWorld;
`;
}

// The form whose attributes the geometry carries ('lobe', 'sh2'), or null.
export function glossyForm(geometry) {
	for (const form of ['lobe', 'sh2']) {
		if (FORMS[form].every((n) => geometry.attributes[n] && geometry.attributes[n].itemSize === 3)) return form;
	}
	return null;
}

// True when the geometry carries a glossy form's attributes.
export function hasGlossyAttributes(geometry) {
	return glossyForm(geometry) !== null;
}

// Makes `material` (a clone is returned) add the glossy light of `form`;
// `uniform` is the shared { value } that scales it (1 on, 0 diffuse only).
function glossyMaterial(material, uniform, form) {
	const m = material.clone();
	m.onBeforeCompile = (shader) => {
		shader.uniforms.triluxGlossy = uniform;
		shader.vertexShader = shader.vertexShader
			.replace('#include <common>', `#include <common>\n${vertex(form)}`)
			.replace('#include <project_vertex>', `#include <project_vertex>
	vTriluxWorld = (modelMatrix * vec4(transformed, 1.0)).xyz;
${FORMS[form].map((n, j) => `	vTrilux${j} = ${n};`).join('\n')}`);
		shader.fragmentShader = shader.fragmentShader
			.replace('#include <common>', `#include <common>\n${fragment(form)}`)
			.replace('#include <color_fragment>', `#include <color_fragment>
	diffuseColor.rgb += triluxGlossy * triluxGlossyLight(normalize(cameraPosition - vTriluxWorld));`);
	};
	m.customProgramCacheKey = () => `trilux-glossy-${form}`;
	m.userData = { ...material.userData, triluxGlossy: true };
	return m;
}

// Gives every mesh under `root` whose geometry has a glossy form a glossy
// material; returns how many meshes.
export function useGlossyAttributes(root, uniform) {
	let n = 0;
	root.traverse((obj) => {
		const form = obj.isMesh ? glossyForm(obj.geometry) : null;
		if (!form) return;
		obj.material = Array.isArray(obj.material)
			? obj.material.map((m) => glossyMaterial(m, uniform, form))
			: glossyMaterial(obj.material, uniform, form);
		n++;
	});
	return n;
}
