// Walk mode: a person's view of an interior. The eye stays EYE_HEIGHT
// above the floor under it (a ray down against the scene, so stairs and
// raised floors are followed) and a step stops short of anything a ray
// along it meets (walls, furniture above knee height), sliding along it:
// the camera never leaves the room for the black outside. Turning is a
// pointer drag (mouse or one finger); moving is WASD / arrows, or two
// fingers (drag or pinch).

import * as THREE from 'three';

/** Eye height above the floor, metres (scene units are metres in trilux). */
export const EYE_HEIGHT = 1.6;
/** A floor-to-ceiling gap lower than EYE_HEIGHT / this puts the eye at this fraction of it. */
const EYE_FRACTION = 0.6;
/** The closest the eye comes to a wall, metres (scaled with the eye height). */
const CLEARANCE = 0.25;
/** A rise the walker steps up, as a fraction of the eye height (a stair, not a table). */
const STEP_FRACTION = 0.3;
/** Walking speed, metres per second (Shift: 3×). */
const SPEED = 1.4;
/** Radians of turn per pixel of drag. */
const TURN_PER_PIXEL = 0.004;
/** Metres of move per pixel of a two-finger drag or pinch. */
const MOVE_PER_PIXEL = 0.01;
const MAX_PITCH = THREE.MathUtils.degToRad(85);

// The 14 directions (axes and cube diagonals) of the "inside" test.
const AROUND = [];
for (const x of [-1, 0, 1]) for (const y of [-1, 0, 1]) for (const z of [-1, 0, 1]) {
	const n = Math.abs(x) + Math.abs(y) + Math.abs(z);
	if (n === 1 || n === 3) AROUND.push(new THREE.Vector3(x, y, z).normalize());
}

export class Walker {
	/**
	 * camera: the THREE camera moved; dom: the canvas (pointer events);
	 * model(): the loaded scene's root or null; changed(): asks for a frame.
	 */
	constructor(camera, dom, model, changed) {
		this.camera = camera;
		this.dom = dom;
		this.model = model;
		this.changed = changed;
		this.enabled = false;
		this.yaw = 0;
		this.pitch = 0;
		this.eye = EYE_HEIGHT;
		this.raycaster = new THREE.Raycaster();
		this.pointers = new Map(); // pointerId → {x, y}
		this.hover = null; // the mouse's last position over the canvas, CSS pixels
		dom.addEventListener('pointerdown', (e) => this.down(e));
		dom.addEventListener('pointermove', (e) => this.drag(e));
		for (const t of ['pointerup', 'pointercancel']) dom.addEventListener(t, (e) => this.up(e));
		dom.addEventListener('pointerleave', (e) => { if (e.pointerType === 'mouse') this.hover = null; });
	}

	/** Starts walking from the camera's pose (kept until the first step). */
	enable() {
		const e = new THREE.Euler().setFromQuaternion(this.camera.quaternion, 'YXZ');
		this.yaw = e.y;
		this.pitch = THREE.MathUtils.clamp(e.x, -MAX_PITCH, MAX_PITCH);
		this.pointers.clear();
		this.enabled = true;
	}

	disable() {
		this.enabled = false;
		this.pointers.clear();
	}

	// ------------------------------------------------------------ rays

	/** The nearest hit of the model along a ray within `far`, or null. */
	cast(origin, dir, far) {
		const root = this.model();
		if (!root) return null;
		this.raycaster.set(origin, dir);
		this.raycaster.near = 0;
		this.raycaster.far = far;
		const hit = this.raycaster.intersectObject(root, true).find((h) => h.object.isMesh);
		return hit ?? null;
	}

	/** Height of the floor under `p` (a ray straight down), or null. */
	floorUnder(p) {
		const hit = this.cast(p, new THREE.Vector3(0, -1, 0), Infinity);
		return hit ? hit.point.y : null;
	}

	/** True when rays from `p` in all 14 directions meet the model: an enclosed point. */
	encloses(p) {
		return AROUND.every((d) => this.cast(p, d, Infinity) !== null);
	}

	/** The eye height over a floor at `floor` under `p`: EYE_HEIGHT, or less under a low ceiling. */
	eyeOver(p, floor) {
		const up = this.cast(new THREE.Vector3(p.x, floor + 1e-3, p.z), new THREE.Vector3(0, 1, 0), Infinity);
		if (!up) return EYE_HEIGHT;
		return Math.min(EYE_HEIGHT, EYE_FRACTION * (up.point.y - floor));
	}

	// ------------------------------------------------------------ moving

	/**
	 * How far the eye may go from `p` along the horizontal unit `dir` and
	 * keep CLEARANCE from the plane of what a ray at eye or knee height
	 * meets first (so a wall met at a slant stops it as far from the wall
	 * as one met head on): { free: metres (Infinity: nothing), normal of
	 * what limits it, horizontal }.
	 */
	room(p, dir, floor) {
		const clearance = CLEARANCE * (this.eye / EYE_HEIGHT);
		const heights = [p.y];
		if (floor !== null) heights.push(floor + STEP_FRACTION * this.eye);
		let best = { free: Infinity, normal: null };
		for (const y of heights) {
			const hit = this.cast(new THREE.Vector3(p.x, y, p.z), dir, Infinity);
			if (!hit) continue;
			const n = hit.face ? hit.face.normal.clone().transformDirection(hit.object.matrixWorld) : dir.clone().negate();
			n.y = 0;
			const cos = n.lengthSq() > 1e-12 ? Math.abs(n.normalize().dot(dir)) : 1;
			const free = hit.distance - clearance / Math.max(cos, 1e-3);
			if (free < best.free) best = { free, normal: n.lengthSq() > 0 ? n : null };
		}
		return best;
	}

	/**
	 * Moves the eye by `forward` and `right` metres in the horizontal frame
	 * of its heading, stopping CLEARANCE short of obstacles and sliding
	 * along them, keeping to ground that has a floor; then sets the eye
	 * height over the floor there. Returns true if the camera moved.
	 */
	step(forward, right) {
		const p = this.camera.position;
		const heading = new THREE.Vector3(-Math.sin(this.yaw), 0, -Math.cos(this.yaw));
		const side = new THREE.Vector3(Math.cos(this.yaw), 0, -Math.sin(this.yaw));
		let move = heading.multiplyScalar(forward).addScaledVector(side, right);
		const floor0 = this.floorUnder(p);
		const to = p.clone();
		for (let i = 0; i < 3 && move.lengthSq() > 1e-12; i++) {
			const dist = move.length();
			const dir = move.clone().divideScalar(dist);
			const { free, normal } = this.room(to, dir, floor0);
			const go = Math.min(dist, Math.max(0, free));
			to.addScaledVector(dir, go);
			if (go === dist || !normal) break;
			// Slide: what is left of the move, less its part into the obstacle.
			move = dir.multiplyScalar(dist - go);
			move.addScaledVector(normal, -move.dot(normal));
		}
		// A slide may cut a corner: the straight way must be free too.
		const way = to.clone().sub(p).setY(0);
		const len = way.length();
		if (len < 1e-9) return this.settle();
		if (this.room(p, way.divideScalar(len), floor0).free < len - 1e-6) return false;
		const floor = this.floorUnder(new THREE.Vector3(to.x, p.y, to.z));
		// Never from a floor onto none (out through an opening into the void).
		if (floor0 !== null && floor === null) return false;
		p.x = to.x;
		p.z = to.z;
		this.settle();
		return true;
	}

	/** Puts the eye at its height over the floor under it (none: unchanged). */
	settle() {
		const p = this.camera.position;
		const floor = this.floorUnder(p);
		if (floor === null) return false;
		this.eye = this.eyeOver(p, floor);
		const moved = Math.abs(p.y - (floor + this.eye)) > 1e-9;
		p.y = floor + this.eye;
		this.changed();
		return moved;
	}

	/** Applies yaw and pitch to the camera. */
	turn(dYaw, dPitch) {
		this.yaw += dYaw;
		this.pitch = THREE.MathUtils.clamp(this.pitch + dPitch, -MAX_PITCH, MAX_PITCH);
		this.camera.quaternion.setFromEuler(new THREE.Euler(this.pitch, this.yaw, 0, 'YXZ'));
		this.changed();
	}

	/** One frame of keyboard walking: `keys` held, `dt` seconds. Returns true while moving. */
	keys(keys, dt) {
		const has = (...c) => c.some((k) => keys.has(k));
		const speed = SPEED * (this.eye / EYE_HEIGHT) * (has('ShiftLeft', 'ShiftRight') ? 3 : 1) * dt;
		let f = 0, r = 0, turn = 0;
		if (has('KeyW', 'ArrowUp')) f += speed;
		if (has('KeyS', 'ArrowDown')) f -= speed;
		if (has('KeyD')) r += speed;
		if (has('KeyA')) r -= speed;
		if (has('ArrowLeft')) turn += 1.5 * dt;
		if (has('ArrowRight')) turn -= 1.5 * dt;
		if (turn) this.turn(turn, 0);
		if (f || r) this.step(f, r);
		return f !== 0 || r !== 0 || turn !== 0;
	}

	// ------------------------------------------------------------ pointers

	down(e) {
		if (!this.enabled) return;
		if (e.pointerType === 'mouse' && e.button !== 0) return;
		this.pointers.set(e.pointerId, { x: e.clientX, y: e.clientY });
		this.dom.setPointerCapture?.(e.pointerId);
		e.preventDefault();
	}

	up(e) {
		this.pointers.delete(e.pointerId);
		this.dom.releasePointerCapture?.(e.pointerId);
	}

	/** One pointer turns; two move: their midpoint's drag walks and strafes, their spread walks forward. */
	drag(e) {
		if (e.pointerType === 'mouse') this.hover = { x: e.clientX, y: e.clientY };
		if (!this.enabled || !this.pointers.has(e.pointerId)) {
			if (e.pointerType === 'mouse') this.changed();
			return;
		}
		const before = [...this.pointers.values()].map((q) => ({ ...q }));
		this.pointers.set(e.pointerId, { x: e.clientX, y: e.clientY });
		const after = [...this.pointers.values()];
		if (after.length === 1) {
			// The scene follows the finger: a drag to the right turns the view left.
			this.turn((after[0].x - before[0].x) * TURN_PER_PIXEL, (after[0].y - before[0].y) * TURN_PER_PIXEL);
		} else if (after.length >= 2) {
			const mid = (ps) => ({ x: (ps[0].x + ps[1].x) / 2, y: (ps[0].y + ps[1].y) / 2 });
			const spread = (ps) => Math.hypot(ps[0].x - ps[1].x, ps[0].y - ps[1].y);
			const m0 = mid(before), m1 = mid(after);
			const k = MOVE_PER_PIXEL * (this.eye / EYE_HEIGHT);
			const forward = ((m1.y - m0.y) + (spread(after) - spread(before))) * k;
			const right = -(m1.x - m0.x) * k;
			this.step(forward, right);
		}
		e.preventDefault();
	}
}
