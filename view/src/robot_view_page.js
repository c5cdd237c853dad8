// inscribe view ROBOT.urdf SPHERES: the robot page's own script, inlined after three.js r147
// (the global THREE) and its OrbitControls by robot_view.cpp. Reads the JSON in the element
// with id inscribe-data (see RobotViewData), poses every link by forward kinematics from the
// joint sliders, and draws each link's geometry (translucent) and spheres in its pose.
//
// Forward kinematics here is robot::Kinematics' (kinematics.h), in double precision: a link's
// pose is its parent's * origin(xyz, rpy) * motion, rpy as R = Rz(yaw) * Ry(pitch) * Rx(roll),
// the motion a rotation by the joint value about `axis` (revolute, continuous) or a
// translation along it (prismatic); a joint's value is multiplier * q[variable] + offset (mimic
// joints follow their leader). Tests compare it with Kinematics::LinkPoses.
//
// URL fragment options (e.g. page.html#color=error&q=0.1,0.2):
//   meshes=0|1, spheres=0|1, panel=0|1   what is shown (default 1)
//   color=link|error    sphere colours: per link, or by how far each reaches outside its link
//   q=v0,v1,...         the configuration, one value per slider (radians or metres, used as
//                       given; the sliders show them clamped to the limits)
//   hide=a,b            links hidden at first
//   dir=x,y,z, up=x,y,z view direction from the centre towards the camera (default 1,0.7,0.55)
//                       and the camera's up (default 0,0,1: URDF is z-up)
//   opacity=a           opacity of the link geometry, 0..1 (default 0.3)
// After each frame the body carries data-spheres-drawn (spheres of the links shown),
// data-sliders (joint sliders) and data-link-poses: every link's pose in the root's frame, in
// link order, 12 numbers each (the 3x4 [R | t] row by row), comma-separated. After the first
// frame the title ends in "(rendered)"; on an error the page shows it and sets data-error.
(function () {
  'use strict';

  const BACKGROUND = 0xf3f4f6;
  const MESH_COLOR = 0x7f9cc0;
  // Tableau 10, for the links.
  const LINK_COLORS = [
    [0.306, 0.475, 0.655], [0.949, 0.557, 0.169], [0.882, 0.341, 0.349], [0.463, 0.718, 0.698],
    [0.349, 0.631, 0.310], [0.929, 0.788, 0.282], [0.690, 0.478, 0.631], [1.000, 0.616, 0.655],
    [0.612, 0.459, 0.373], [0.729, 0.690, 0.675],
  ];
  // Protrusion, as the mesh page: grey inside, yellow to red by how far out; violet unknown.
  const NOT_PROTRUDING = [0.66, 0.68, 0.71];
  const PROTRUDING = [[1.0, 0.86, 0.16], [0.98, 0.55, 0.12], [0.80, 0.08, 0.10]];
  const UNKNOWN = [0.58, 0.45, 0.80];

  let rendered = false;

  function showError(error) {
    const text = error && error.stack ? String(error.stack) : String(error);
    document.body.dataset.error = text.split('\n')[0];
    const box = document.getElementById('error');
    box.textContent = 'inscribe view: ' + text;
    box.hidden = false;
    if (!/\(error\)$/.test(document.title)) document.title += ' (error)';
  }
  window.addEventListener('error', (event) => showError(event.error || event.message));

  function readOptions(data) {
    const p = new URLSearchParams(window.location.hash.replace(/^#/, ''));
    const flag = (name) => !p.has(name) || !['0', 'false', 'off', 'no'].includes(p.get(name));
    const vector = (name, fallback) => {
      const v = (p.get(name) || '').split(',').map(Number);
      return v.length === 3 && v.every(Number.isFinite) && v.some((x) => x !== 0) ? v : fallback;
    };
    const opacity = Number(p.get('opacity'));
    const q = (p.get('q') || '').split(',').filter((s) => s !== '').map(Number);
    return {
      meshes: flag('meshes'),
      spheres: flag('spheres'),
      panel: flag('panel'),
      color: p.get('color') === 'error' ? 'error' : 'link',
      q: q.length === data.variables.length && q.every(Number.isFinite) ? q : null,
      hide: new Set((p.get('hide') || '').split(',').filter((s) => s !== '')),
      dir: vector('dir', [1, 0.7, 0.55]),
      up: vector('up', [0, 0, 1]),
      opacity: p.has('opacity') && opacity >= 0 && opacity <= 1 ? opacity : 0.3,
    };
  }

  // ---- forward kinematics: poses as [R | t], 12 numbers row by row --------------------------
  const IDENTITY = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0];
  function compose(a, b) {
    const c = new Array(12);
    for (let i = 0; i < 3; ++i) {
      for (let j = 0; j < 4; ++j) {
        let sum = j === 3 ? a[4 * i + 3] : 0;
        for (let k = 0; k < 3; ++k) sum += a[4 * i + k] * b[4 * k + j];
        c[4 * i + j] = sum;
      }
    }
    return c;
  }
  function originPose(xyz, rpy) {
    const [cr, sr] = [Math.cos(rpy[0]), Math.sin(rpy[0])];
    const [cp, sp] = [Math.cos(rpy[1]), Math.sin(rpy[1])];
    const [cy, sy] = [Math.cos(rpy[2]), Math.sin(rpy[2])];
    return [
      cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr, xyz[0],
      sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr, xyz[1],
      -sp, cp * sr, cp * cr, xyz[2],
    ];
  }
  function motion(joint, value) {
    const [x, y, z] = joint.axis;
    if (joint.type === 'prismatic') return [1, 0, 0, x * value, 0, 1, 0, y * value, 0, 0, 1, z * value];
    if (joint.type !== 'revolute' && joint.type !== 'continuous') return IDENTITY;
    const c = Math.cos(value), s = Math.sin(value), t = 1 - c;
    return [
      c + t * x * x, t * x * y - s * z, t * x * z + s * y, 0,
      t * x * y + s * z, c + t * y * y, t * y * z - s * x, 0,
      t * x * z - s * y, t * y * z + s * x, c + t * z * z, 0,
    ];
  }
  // Every link's pose in the root link's frame at configuration q.
  function linkPoses(data, q) {
    const poses = new Array(data.links.length);
    for (const l of data.order) {
      const link = data.links[l];
      if (link.parent < 0) {
        poses[l] = IDENTITY;
        continue;
      }
      const joint = data.joints[link.joint];
      const value = joint.variable >= 0 ? joint.multiplier * q[joint.variable] + joint.offset : 0;
      poses[l] = compose(compose(poses[link.parent], originPose(joint.xyz, joint.rpy)),
                         motion(joint, value));
    }
    return poses;
  }

  // ---- formatting and colours --------------------------------------------------------------
  function num(x, digits = 4) {
    if (!Number.isFinite(x)) return String(x);
    if (x === 0) return '0';
    return String(Number(x.toPrecision(digits)));
  }
  function plural(n, word) {
    return n + ' ' + word + (n === 1 ? '' : 's');
  }
  function element(tag, attributes = {}, text) {
    const e = document.createElement(tag);
    for (const [key, value] of Object.entries(attributes)) e.setAttribute(key, value);
    if (text !== undefined) e.textContent = text;
    return e;
  }
  function ramp(stops, t) {
    const x = Math.min(Math.max(t, 0), 1) * (stops.length - 1);
    const i = Math.min(Math.floor(x), stops.length - 2);
    const f = x - i;
    return stops[i].map((a, k) => a + (stops[i + 1][k] - a) * f);
  }
  function cssColor(rgb) {
    return 'rgb(' + rgb.map((c) => Math.round(255 * c)).join(',') + ')';
  }
  function linkColor(l) {
    return LINK_COLORS[l % LINK_COLORS.length];
  }
  function sphereColor(data, l, i, mode) {
    if (mode === 'link') return linkColor(l);
    const g = data.geometry[l];
    if (g.protrusion === null) return UNKNOWN;
    const p = g.protrusion[i];
    const top = data.spheres.protrusion_max > 0 ? data.spheres.protrusion_max : 1;
    return p > g.tolerance ? ramp(PROTRUDING, p / top) : NOT_PROTRUDING;
  }

  // ---- the 3D objects of one link, in its own frame ---------------------------------------
  function buildLink(data, l, options, sphereGeometry) {
    const g = data.geometry[l];
    const group = new THREE.Group();
    group.matrixAutoUpdate = false;
    const geometryMaterial = new THREE.MeshPhongMaterial({
      color: MESH_COLOR,
      transparent: true,
      opacity: options.opacity,
      side: THREE.DoubleSide,
      depthWrite: false,
      shininess: 10,
    });
    const solids = new THREE.Group();
    for (const m of g.meshes) {
      const geometry = new THREE.BufferGeometry();
      geometry.setAttribute('position', new THREE.Float32BufferAttribute(m.vertices, 3));
      geometry.setIndex(m.triangles);
      geometry.computeVertexNormals();
      const mesh = new THREE.Mesh(geometry, geometryMaterial);
      mesh.renderOrder = 1;  // after the opaque spheres, blended over them
      solids.add(mesh);
    }
    for (let i = 0; i < g.shapes.length / 4; ++i) {
      const r = g.shapes[4 * i + 3];
      const ball = new THREE.Mesh(sphereGeometry, geometryMaterial);
      ball.position.set(g.shapes[4 * i], g.shapes[4 * i + 1], g.shapes[4 * i + 2]);
      ball.scale.set(r, r, r);
      ball.renderOrder = 1;
      solids.add(ball);
    }
    const n = g.spheres.length / 4;
    let spheres = null;
    if (n > 0) {
      const material = new THREE.MeshPhongMaterial({color: 0xffffff, shininess: 30});
      spheres = new THREE.InstancedMesh(sphereGeometry, material, n);
      spheres.frustumCulled = false;  // r147 culls by the one geometry's bounds
      const matrix = new THREE.Matrix4();
      for (let i = 0; i < n; ++i) {
        const r = g.spheres[4 * i + 3];
        matrix.makeScale(r, r, r);
        matrix.setPosition(g.spheres[4 * i], g.spheres[4 * i + 1], g.spheres[4 * i + 2]);
        spheres.setMatrixAt(i, matrix);
      }
      spheres.instanceMatrix.needsUpdate = true;
      group.add(spheres);
    }
    group.add(solids);
    return {group, solids, spheres, count: n};
  }

  function paintLink(data, l, object, mode) {
    if (!object.spheres) return;
    const color = new THREE.Color();
    for (let i = 0; i < object.count; ++i) {
      object.spheres.setColorAt(i, color.setRGB(...sphereColor(data, l, i, mode)));
    }
    object.spheres.instanceColor.needsUpdate = true;
  }

  // Bounds, in the root frame, of every link's geometry and spheres at `poses`.
  function sceneBounds(data, poses) {
    const box = new THREE.Box3();
    data.geometry.forEach((g, l) => {
      const m = new THREE.Matrix4().set(...poses[l], 0, 0, 0, 1);
      for (const list of [g.shapes, g.spheres]) {
        for (let i = 0; i < list.length / 4; ++i) {
          const c = new THREE.Vector3(list[4 * i], list[4 * i + 1], list[4 * i + 2]).applyMatrix4(m);
          box.expandByPoint(c.clone().addScalar(list[4 * i + 3]));
          box.expandByPoint(c.addScalar(-list[4 * i + 3]));
        }
      }
      for (const mesh of g.meshes) {
        const local = new THREE.Box3().setFromArray(mesh.vertices);
        if (!local.isEmpty()) box.union(local.applyMatrix4(m));
      }
    });
    if (box.isEmpty()) box.set(new THREE.Vector3(-1, -1, -1), new THREE.Vector3(1, 1, 1));
    return {center: box.getCenter(new THREE.Vector3()),
            radius: Math.max(1e-9, box.getSize(new THREE.Vector3()).length() / 2)};
  }

  // ---- the panel -----------------------------------------------------------------------------
  function summaryTable(data) {
    const s = data.spheres;
    const problems = data.geometry.reduce((n, g) => n + g.problems.length, 0);
    const rows = [
      ['robot', (data.robot.name || '(unnamed)') + ' (' + data.robot.file + '): ' +
        plural(data.robot.links, 'link') + ', ' + plural(data.robot.joints, 'joint') + ', ' +
        plural(data.variables.length, 'variable')],
      ['spheres', s.count + ' (' + s.file + ', ' + s.format + ')'],
      ['protrusion', plural(s.protruding, 'sphere') + ' reaching outside its link; max ' +
        num(s.protrusion_max) + ' m', 'per sphere: max(0, r + signed distance of the centre ' +
        'to its link\'s geometry), metres'],
      ['problems', problems === 0 ? 'none' : problems + ' (see the links)'],
    ];
    const table = element('table', {class: 'report'});
    for (const [key, value, hint] of rows) {
      const tr = table.insertRow();
      tr.appendChild(element('th', {}, key));
      tr.appendChild(element('td', hint ? {title: hint} : {}, value));
    }
    return table;
  }

  function main() {
    const data = JSON.parse(document.getElementById('inscribe-data').textContent);
    let options = readOptions(data);
    const body = document.body;
    body.classList.add('robot');
    const panel = document.getElementById('panel');
    const viewport = document.getElementById('viewport');
    let q = options.q ? options.q.slice() : data.variables.map((v) => v.value);

    panel.appendChild(element('h1', {}, data.title));
    panel.appendChild(element('div', {class: 'subtitle'},
                              'inscribe view \u00b7 a robot\'s links and their spheres'));
    panel.appendChild(summaryTable(data));

    // Joint sliders: one per variable; mimic joints follow.
    panel.appendChild(element('h2', {}, 'joints'));
    const sliders = [];
    const jointsBox = element('div', {class: 'joints'});
    data.variables.forEach((v, i) => {
      const row = element('label', {class: 'joint'});
      const unit = v.type === 'prismatic' ? ' m' : ' rad';
      const name = element('span', {class: 'name', title: v.type + ', ' + num(v.lower) + ' \u2013 ' +
                                    num(v.upper) + unit}, v.joint);
      const span = v.upper - v.lower;
      const slider = element('input', {type: 'range', class: 'joint-slider', 'data-joint': v.joint,
                                       min: String(v.lower), max: String(v.upper),
                                       step: span > 0 ? String(span / 1000) : '1'});
      if (!(span > 0)) slider.disabled = true;
      const value = element('span', {class: 'value'});
      row.append(name, slider, value);
      jointsBox.appendChild(row);
      sliders.push({slider, value, unit});
      slider.addEventListener('input', () => {
        q[i] = Number(slider.value);
        value.textContent = num(q[i], 3) + unit;
        pose();
        requestRender();
      });
    });
    const mimics = data.joints.filter((j) => j.mimic !== null);
    if (mimics.length > 0) {
      jointsBox.appendChild(element('div', {class: 'note'}, 'follow their leader: ' +
          mimics.map((j) => j.name + ' (' + j.mimic + ')').join(', ')));
    }
    if (data.variables.length === 0) jointsBox.appendChild(element('div', {class: 'note'}, 'none'));
    panel.appendChild(jointsBox);
    const zero = element('button', {type: 'button'}, 'home');
    zero.addEventListener('click', () => {
      q = data.variables.map((v) => v.value);
      syncSliders();
      pose();
      requestRender();
    });
    panel.appendChild(zero);

    panel.appendChild(element('h2', {}, 'display'));
    const controls = element('div', {class: 'controls'});
    const meshBox = element('input', {type: 'checkbox', id: 'show-meshes'});
    const spheresBox = element('input', {type: 'checkbox', id: 'show-spheres'});
    const colorSelect = element('select', {id: 'color-by'});
    colorSelect.append(element('option', {value: 'link'}, 'link'),
                       element('option', {value: 'error'}, 'error (protrusion)'));
    const meshLabel = element('label', {}, ' links\' geometry');
    meshLabel.prepend(meshBox);
    const spheresLabel = element('label', {}, ' spheres');
    spheresLabel.prepend(spheresBox);
    const colorLabel = element('label', {}, 'colour by ');
    colorLabel.append(colorSelect);
    controls.append(meshLabel, spheresLabel, colorLabel);
    panel.appendChild(controls);
    const legend = element('div', {class: 'note legend-text'});
    panel.appendChild(legend);
    function drawLegend() {
      legend.replaceChildren();
      if (options.color !== 'error') {
        legend.textContent = 'each link\'s colour is the swatch beside its name';
        return;
      }
      const swatch = (rgb, text) => {
        const s = element('span', {class: 'swatch'});
        s.style.background = cssColor(rgb);
        legend.append(s, ' ' + text + '  ');
      };
      swatch(NOT_PROTRUDING, 'inside');
      if (data.spheres.protruding > 0) {
        swatch(PROTRUDING[0], '> 0');
        swatch(PROTRUDING[2], num(data.spheres.protrusion_max, 3) + ' m');
      } else {
        legend.append('(none reaches outside)  ');
      }
      swatch(UNKNOWN, 'unknown');
    }

    // Links: a checkbox each, their spheres and problems.
    panel.appendChild(element('h2', {}, 'links'));
    const linkList = element('div', {class: 'links'});
    const linkBoxes = [];
    data.links.forEach((link, l) => {
      const g = data.geometry[l];
      const row = element('div', {class: 'link'});
      const label = element('label', {});
      const box = element('input', {type: 'checkbox', 'data-link': link.name});
      const swatch = element('span', {class: 'swatch'});
      swatch.style.background = cssColor(linkColor(l));
      let worst = 0;
      if (g.protrusion !== null) for (const p of g.protrusion) worst = Math.max(worst, p);
      const facts = plural(g.spheres.length / 4, 'sphere') +
          (g.spheres.length === 0 ? '' : g.protrusion === null ? ', protrusion unknown'
                                                                : ', max protrusion ' + num(worst, 3));
      label.append(box, swatch, element('span', {class: 'name'}, link.name),
                   element('span', {class: 'note'}, ' ' + facts));
      row.appendChild(label);
      for (const problem of g.problems) {
        row.appendChild(element('div', {class: 'problem'}, problem));
      }
      linkList.appendChild(row);
      linkBoxes.push(box);
      box.addEventListener('change', () => {
        if (box.checked) options.hide.delete(link.name); else options.hide.add(link.name);
        apply();
        requestRender();
      });
    });
    panel.appendChild(linkList);

    // Scene.
    const renderer = new THREE.WebGLRenderer({antialias: true});
    renderer.setPixelRatio(window.devicePixelRatio || 1);
    viewport.appendChild(renderer.domElement);
    const scene = new THREE.Scene();
    scene.background = new THREE.Color(BACKGROUND);
    const camera = new THREE.PerspectiveCamera(30, 1, 1e-3, 1e3);
    scene.add(camera);
    scene.add(new THREE.HemisphereLight(0xffffff, 0x60656e, 0.55));
    const headLight = new THREE.DirectionalLight(0xffffff, 0.7);
    headLight.position.set(-0.4, 0.8, 1.0);
    headLight.target.position.set(0, 0, -1);
    camera.add(headLight, headLight.target);
    const sphereGeometry = new THREE.SphereGeometry(1, 24, 16);
    const objects = data.links.map((link, l) => buildLink(data, l, options, sphereGeometry));
    for (const object of objects) scene.add(object.group);
    camera.up.set(...options.up).normalize();
    const orbit = new THREE.OrbitControls(camera, renderer.domElement);

    function syncSliders() {
      sliders.forEach(({slider, value, unit}, i) => {
        slider.value = String(q[i]);
        value.textContent = num(q[i], 3) + unit;
      });
    }

    let poses = [];
    function pose() {
      poses = linkPoses(data, q);
      objects.forEach((object, l) => {
        object.group.matrix.set(...poses[l], 0, 0, 0, 1);
        object.group.matrixWorldNeedsUpdate = true;
      });
      body.dataset.linkPoses = poses.map((p) => p.map(String).join(',')).join(',');
    }

    function frame() {
      const width = Math.max(1, viewport.clientWidth);
      const height = Math.max(1, viewport.clientHeight);
      renderer.setSize(width, height);
      camera.aspect = width / height;
      const bounds = sceneBounds(data, poses);
      const halfVertical = THREE.MathUtils.degToRad(camera.fov / 2);
      const halfHorizontal = Math.atan(Math.tan(halfVertical) * camera.aspect);
      const distance = 1.04 * bounds.radius / Math.sin(Math.min(halfVertical, halfHorizontal));
      const dir = new THREE.Vector3(...options.dir).normalize();
      camera.position.copy(bounds.center).addScaledVector(dir, distance);
      camera.near = distance / 100;
      camera.far = distance * 10;
      camera.updateProjectionMatrix();
      orbit.target.copy(bounds.center);
      orbit.update();
    }

    function render() {
      renderer.render(scene, camera);
      let drawn = 0;
      objects.forEach((object) => {
        if (object.group.visible && object.spheres && object.spheres.visible) drawn += object.count;
      });
      body.dataset.spheresDrawn = String(drawn);
      body.dataset.sliders = String(sliders.length);
      if (!rendered) {
        rendered = true;
        document.title += ' (rendered)';
      }
    }
    let queued = false;
    function requestRender() {
      if (queued) return;
      queued = true;
      window.requestAnimationFrame(() => {
        queued = false;
        render();
      });
    }

    function apply() {
      body.classList.toggle('no-panel', !options.panel);
      meshBox.checked = options.meshes;
      spheresBox.checked = options.spheres;
      colorSelect.value = options.color;
      objects.forEach((object, l) => {
        const shown = !options.hide.has(data.links[l].name);
        linkBoxes[l].checked = shown;
        object.group.visible = shown;
        object.solids.visible = options.meshes;
        object.solids.children.forEach((child) => { child.material.opacity = options.opacity; });
        if (object.spheres) object.spheres.visible = options.spheres;
        paintLink(data, l, object, options.color);
      });
      drawLegend();
    }

    meshBox.addEventListener('change', () => {
      options.meshes = meshBox.checked;
      apply();
      requestRender();
    });
    spheresBox.addEventListener('change', () => {
      options.spheres = spheresBox.checked;
      apply();
      requestRender();
    });
    colorSelect.addEventListener('change', () => {
      options.color = colorSelect.value;
      apply();
      requestRender();
    });
    window.addEventListener('hashchange', () => {
      options = readOptions(data);
      if (options.q) q = options.q.slice();
      syncSliders();
      pose();
      apply();
      frame();
      requestRender();
    });
    window.addEventListener('resize', () => {
      const width = Math.max(1, viewport.clientWidth);
      const height = Math.max(1, viewport.clientHeight);
      renderer.setSize(width, height);
      camera.aspect = width / height;
      camera.updateProjectionMatrix();
      requestRender();
    });
    orbit.addEventListener('change', requestRender);

    syncSliders();
    pose();
    apply();
    frame();
    render();
  }

  try {
    main();
  } catch (error) {
    showError(error);
  }
})();
