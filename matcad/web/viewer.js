// A small 3-D viewer without dependencies: flat-shaded triangles on a 2-D canvas, sorted back to front (painter's
// algorithm), orthographic, turned by dragging. Parts: [{name, colour "#rrggbb", vertices [x,y,z,...] mm,
// triangles [i,j,k,...]}] in the assembly frame (z up).
function makeViewer(canvas) {
  const ctx = canvas.getContext("2d");
  let tris = [], centre = [0, 0, 0], radius = 1, yaw = -0.6, pitch = 0.5;
  const light = (() => { const v = [0.4, -0.5, 0.75]; const n = Math.hypot(...v); return v.map((c) => c / n); })();

  function show(parts) {
    tris = [];
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (const part of parts) {
      const v = part.vertices, rgb = [1, 3, 5].map((i) => parseInt(part.colour.slice(i, i + 2), 16));
      for (let i = 0; i < v.length; i += 3) for (let k = 0; k < 3; k++) {
        lo[k] = Math.min(lo[k], v[i + k]); hi[k] = Math.max(hi[k], v[i + k]);
      }
      for (let t = 0; t < part.triangles.length; t += 3) {
        const [a, b, c] = [0, 1, 2].map((j) => part.triangles[t + j] * 3);
        const p = [a, b, c].map((i) => [v[i], v[i + 1], v[i + 2]]);
        const u = p[1].map((x, k) => x - p[0][k]), w = p[2].map((x, k) => x - p[0][k]);
        const n = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]];
        const len = Math.hypot(...n) || 1;
        tris.push({p, n: n.map((x) => x / len), rgb});
      }
    }
    centre = lo.map((x, k) => (x + hi[k]) / 2);
    radius = Math.max(1e-3, Math.hypot(...hi.map((x, k) => x - lo[k])) / 2);
    draw();
  }

  function rotate(q) {  // turn about z by yaw, then tilt about the screen's x by pitch; z of the result = depth
    const x = q[0] - centre[0], y = q[1] - centre[1], z = q[2] - centre[2];
    const cy = Math.cos(yaw), sy = Math.sin(yaw), cp = Math.cos(pitch), sp = Math.sin(pitch);
    const x1 = cy * x - sy * y, y1 = sy * x + cy * y;
    return [x1, cp * z - sp * y1, sp * z + cp * y1];  // screen right, screen up, towards the viewer
  }

  function draw() {
    ctx.clearRect(0, 0, canvas.width, canvas.height);
    const s = 0.46 * Math.min(canvas.width, canvas.height) / radius, cx = canvas.width / 2, cy = canvas.height / 2;
    const view = tris.map((t) => {
      const r = t.p.map(rotate);
      const n = rotate([t.n[0] + centre[0], t.n[1] + centre[1], t.n[2] + centre[2]]);
      return {r, depth: (r[0][2] + r[1][2] + r[2][2]) / 3, n, rgb: t.rgb};
    });
    view.sort((a, b) => a.depth - b.depth);
    const lv = rotate([light[0] + centre[0], light[1] + centre[1], light[2] + centre[2]]);
    for (const t of view) {
      const shade = 0.35 + 0.65 * Math.abs(t.n[0] * lv[0] + t.n[1] * lv[1] + t.n[2] * lv[2]);
      ctx.fillStyle = `rgb(${t.rgb.map((c) => Math.round(c * shade)).join(",")})`;
      ctx.beginPath();
      t.r.forEach((q, i) => (i ? ctx.lineTo : ctx.moveTo).call(ctx, cx + s * q[0], cy - s * q[1]));
      ctx.closePath();
      ctx.fill();
      ctx.strokeStyle = ctx.fillStyle;  // closes the hairline gaps between neighbours
      ctx.lineWidth = 0.5;
      ctx.stroke();
    }
  }

  let drag = null;
  canvas.addEventListener("pointerdown", (e) => { drag = [e.clientX, e.clientY, yaw, pitch]; canvas.setPointerCapture(e.pointerId); });
  canvas.addEventListener("pointerup", () => { drag = null; });
  canvas.addEventListener("pointermove", (e) => {
    if (!drag) return;
    yaw = drag[2] + (e.clientX - drag[0]) * 0.01;
    pitch = Math.max(-1.5, Math.min(1.5, drag[3] + (e.clientY - drag[1]) * 0.01));
    draw();
  });
  return {show, triangles: () => tris.length};
}
