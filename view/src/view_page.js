// inscribe view: the page's own script, inlined after three.js r147 (the global THREE) and its
// OrbitControls (THREE.OrbitControls) by view_report_html.cpp. Reads the JSON in the
// element with id inscribe-data (see ViewPageData), draws the mesh (translucent) and the spheres
// (one instanced mesh) and fills the panel with the report and the paper's Fig. 7 histograms.
//
// URL fragment options, for links, tests and screenshots (e.g. page.html#mesh=0&color=protrusion):
//   mesh=0|1            show the mesh (default 1)
//   spheres=0|1         show the spheres (default 1)
//   color=radius|protrusion   what the sphere colours mean (default radius)
//   panel=0|1           show the panel (default 1)
//   dir=x,y,z           view direction, from the model's centre towards the camera (default 0,0,1)
//   up=x,y,z            the camera's up direction (default 0,1,0; read when the page opens)
//   opacity=a           opacity of the mesh, 0..1 (default 0.25)
// After each frame the body's data-spheres-drawn attribute holds the number of spheres drawn
// (0 when hidden) and, after the first, the title ends in "(rendered)"; on an error the page
// shows it and sets the body's data-error attribute to its first line. Tests read both with
// `chromium --dump-dom`.
(function () {
  'use strict';

  const BACKGROUND = 0xf3f4f6;
  const MESH_COLOR = 0x7f9cc0;
  // Matplotlib's viridis at 11 stops, for radius.
  const VIRIDIS = [
    [0.267, 0.005, 0.329], [0.283, 0.141, 0.458], [0.254, 0.265, 0.530], [0.207, 0.372, 0.553],
    [0.164, 0.471, 0.558], [0.128, 0.567, 0.551], [0.135, 0.659, 0.518], [0.267, 0.749, 0.441],
    [0.478, 0.821, 0.318], [0.741, 0.873, 0.150], [0.993, 0.906, 0.144],
  ];
  // Protrusion: grey when the sphere stays inside, yellow to red by how far it reaches out.
  const NOT_PROTRUDING = [0.66, 0.68, 0.71];
  const PROTRUDING = [[1.0, 0.86, 0.16], [0.98, 0.55, 0.12], [0.80, 0.08, 0.10]];
  const NEGATIVE_BARS = '#4c78a8';  // histogram bins below 0: the envelope inside the mesh
  const POSITIVE_BARS = '#e4572e';  // above 0: outside

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

  function readOptions() {
    const p = new URLSearchParams(window.location.hash.replace(/^#/, ''));
    const flag = (name) => !p.has(name) || !['0', 'false', 'off', 'no'].includes(p.get(name));
    const vector = (name, fallback) => {
      const v = (p.get(name) || '').split(',').map(Number);
      return v.length === 3 && v.every(Number.isFinite) && v.some((x) => x !== 0) ? v : fallback;
    };
    const opacity = Number(p.get('opacity'));
    return {
      mesh: flag('mesh'),
      spheres: flag('spheres'),
      panel: flag('panel'),
      color: p.get('color') === 'protrusion' ? 'protrusion' : 'radius',
      dir: vector('dir', [0, 0, 1]),
      up: vector('up', [0, 1, 0]),
      opacity: p.has('opacity') && opacity >= 0 && opacity <= 1 ? opacity : 0.25,
    };
  }

  // ---- formatting --------------------------------------------------------------------------
  function num(x, digits = 4) {
    if (!Number.isFinite(x)) return String(x);
    if (x === 0) return '0';
    return String(Number(x.toPrecision(digits)));
  }
  function count(n) {
    return Number(n).toLocaleString('en-US');
  }
  function percent(x, digits = 3) {
    return num(100 * x, digits) + ' %';
  }
  function element(tag, attributes = {}, text) {
    const e = document.createElement(tag);
    for (const [key, value] of Object.entries(attributes)) e.setAttribute(key, value);
    if (text !== undefined) e.textContent = text;
    return e;
  }

  // ---- colours -----------------------------------------------------------------------------
  function ramp(stops, t) {
    const x = Math.min(Math.max(t, 0), 1) * (stops.length - 1);
    const i = Math.min(Math.floor(x), stops.length - 2);
    const f = x - i;
    return stops[i].map((a, k) => a + (stops[i + 1][k] - a) * f);
  }
  function cssColor(rgb) {
    return 'rgb(' + rgb.map((c) => Math.round(255 * c)).join(',') + ')';
  }
  function sphereColors(data, mode) {
    const n = data.spheres.count;
    const xyzr = data.spheres.xyzr;
    const colors = new Array(n);
    if (mode === 'protrusion') {
      const report = data.report;
      const top = report.protrusion_max > 0 ? report.protrusion_max : 1;
      for (let i = 0; i < n; ++i) {
        const p = data.spheres.protrusion[i];
        colors[i] = p > report.protrusion_tolerance ? ramp(PROTRUDING, p / top) : NOT_PROTRUDING;
      }
    } else {
      const low = data.report.radius_min;
      const span = data.report.radius_max - low;
      for (let i = 0; i < n; ++i) {
        colors[i] = ramp(VIRIDIS, span > 0 ? (xyzr[4 * i + 3] - low) / span : 0.5);
      }
    }
    return colors;
  }

  // ---- the panel ---------------------------------------------------------------------------
  function reportTable(data) {
    const r = data.report;
    const diagonal = data.mesh.bbox.diagonal || 1;
    const t = data.timing;
    const rows = [
      ['mesh', data.mesh.name + ': ' + count(data.mesh.vertices.length / 3) + ' vertices, ' +
        count(data.mesh.triangles.length / 3) + ' triangles', data.mesh.sha256],
      ['spheres', count(data.spheres.count) + ' (' + data.spheres.name + ')'],
      ['nerr', num(r.nerr) + (r.nerr_is_exact ? ' (exact)' : ' (lower bound)'),
        r.nerr_is_exact ? 'no sphere protrudes: Err/vol = (vol mesh - vol union) / vol mesh'
          : 'spheres protrude: Lemma 1 lower bound |vol union - vol mesh| / vol mesh'],
      ['protrusion', count(r.protruding_spheres) + ' spheres protrude; max ' +
        num(r.protrusion_max) + ' (' + percent(r.protrusion_max / diagonal) +
        ' of the diagonal), mean ' + num(r.protrusion_mean),
        'per sphere: max(0, r + signed distance of the centre), mesh units'],
      ['coverage', percent(r.coverage, 4) + ' of ' + count(r.surface_samples) +
        ' boundary samples within ' + num(r.coverage_tolerance, 3) + ' of the union'],
      ['Hausdorff', num(r.boundary_to_union_hausdorff) + ' boundary \u2192 union (' +
        percent(r.boundary_to_union_hausdorff / diagonal) + ' of the diagonal ' +
        num(diagonal) + ')'],
      ['radius', num(r.radius_min) + ' \u2013 ' + num(r.radius_max)],
      ['time', 'load ' + num(t.load, 2) + ' s, evaluate ' + num(t.evaluate, 2) +
        ' s, envelope ' + num(t.envelope, 2) + ' s'],
    ];
    const table = element('table', {class: 'report'});
    for (const [key, value, hint] of rows) {
      const tr = table.insertRow();
      tr.appendChild(element('th', {}, key));
      const td = element('td', hint ? {title: hint} : {}, value);
      tr.appendChild(td);
    }
    return table;
  }

  function drawLegend(canvas, ticks, data, mode) {
    const width = canvas.clientWidth || 300;
    canvas.width = width;
    canvas.height = 10;
    const ctx = canvas.getContext('2d');
    ticks.replaceChildren();
    if (mode === 'protrusion') {
      const grey = Math.round(width * 0.2);
      ctx.fillStyle = cssColor(NOT_PROTRUDING);
      ctx.fillRect(0, 0, grey, 10);
      for (let x = grey; x < width; ++x) {
        ctx.fillStyle = cssColor(ramp(PROTRUDING, (x - grey) / Math.max(1, width - grey - 1)));
        ctx.fillRect(x, 0, 1, 10);
      }
      const top = data.report.protruding_spheres > 0 ? num(data.report.protrusion_max, 3)
                                                     : 'none protrudes';
      ticks.append(element('span', {}, 'inside'), element('span', {}, '> 0'),
                   element('span', {}, top));
    } else {
      for (let x = 0; x < width; ++x) {
        ctx.fillStyle = cssColor(ramp(VIRIDIS, x / Math.max(1, width - 1)));
        ctx.fillRect(x, 0, 1, 10);
      }
      ticks.append(element('span', {}, 'r ' + num(data.report.radius_min, 3)),
                   element('span', {}, num(data.report.radius_max, 3)));
    }
  }

  // Fig. 7-style histogram: bars per bin (fraction of samples), the zero line, and dashed lines
  // at +-mean |d|.
  function drawHistogram(canvas, h) {
    const ratio = window.devicePixelRatio || 1;
    const width = canvas.clientWidth || 300;
    const height = canvas.clientHeight || 92;
    canvas.width = Math.round(width * ratio);
    canvas.height = Math.round(height * ratio);
    const ctx = canvas.getContext('2d');
    ctx.scale(ratio, ratio);
    const left = 4, right = 4, top = 14, bottom = 16;
    const plotWidth = width - left - right;
    const plotHeight = height - top - bottom;
    const lo = h.edges[0];
    const hi = h.edges[h.edges.length - 1];
    const x = (v) => left + (v - lo) / (hi - lo) * plotWidth;
    const samples = Math.max(1, h.samples);
    const peak = Math.max(1, ...h.counts) / samples;
    ctx.font = '10px "DejaVu Sans", sans-serif';
    for (let i = 0; i < h.counts.length; ++i) {
      const fraction = h.counts[i] / samples;
      const barHeight = fraction / peak * plotHeight;
      if (barHeight <= 0) continue;
      ctx.fillStyle = h.edges[i] >= 0 ? POSITIVE_BARS : NEGATIVE_BARS;
      const x0 = x(h.edges[i]);
      const x1 = x(h.edges[i + 1]);
      ctx.fillRect(x0, top + plotHeight - barHeight, Math.max(1, x1 - x0 - 0.5),
                   Math.max(1, barHeight));
    }
    ctx.strokeStyle = '#30343a';
    ctx.lineWidth = 1;
    ctx.beginPath();
    ctx.moveTo(left, top + plotHeight + 0.5);
    ctx.lineTo(left + plotWidth, top + plotHeight + 0.5);
    ctx.moveTo(Math.round(x(0)) + 0.5, top - 2);
    ctx.lineTo(Math.round(x(0)) + 0.5, top + plotHeight);
    ctx.stroke();
    ctx.setLineDash([3, 3]);
    ctx.strokeStyle = '#111';
    ctx.beginPath();
    for (const m of [-h.mean_absolute, h.mean_absolute]) {
      ctx.moveTo(Math.round(x(m)) + 0.5, top);
      ctx.lineTo(Math.round(x(m)) + 0.5, top + plotHeight);
    }
    ctx.stroke();
    ctx.setLineDash([]);
    ctx.fillStyle = '#30343a';
    ctx.textBaseline = 'top';
    ctx.textAlign = 'left';
    ctx.fillText(num(lo, 3), left, top + plotHeight + 3);
    ctx.textAlign = 'center';
    ctx.fillText('0', x(0), top + plotHeight + 3);
    ctx.textAlign = 'right';
    ctx.fillText(num(hi, 3), left + plotWidth, top + plotHeight + 3);
    ctx.textBaseline = 'alphabetic';
    ctx.textAlign = 'left';
    ctx.fillText('peak ' + percent(peak, 3), left, 10);
    ctx.textAlign = 'right';
    ctx.fillText('- - mean |d|', left + plotWidth, 10);
  }

  function histogramBlock(panel, title, h) {
    panel.appendChild(element('h2', {}, title));
    panel.appendChild(element(
        'div', {class: 'note'},
        count(h.samples) + ' samples, mean |d| ' + num(h.mean_absolute, 3) + ', min ' +
            num(h.min, 3) + ', max ' + num(h.max, 3)));
    const canvas = element('canvas', {class: 'histogram'});
    panel.appendChild(canvas);
    return canvas;
  }

  // ---- the 3D view -------------------------------------------------------------------------
  function buildMesh(data, options) {
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.Float32BufferAttribute(data.mesh.vertices, 3));
    geometry.setIndex(data.mesh.triangles);
    geometry.computeVertexNormals();
    const material = new THREE.MeshPhongMaterial({
      color: MESH_COLOR,
      transparent: true,
      opacity: options.opacity,
      side: THREE.DoubleSide,
      depthWrite: false,
      shininess: 10,
    });
    const mesh = new THREE.Mesh(geometry, material);
    mesh.renderOrder = 1;  // after the opaque spheres, blended over them
    return mesh;
  }

  function buildSpheres(data) {
    const n = data.spheres.count;
    const xyzr = data.spheres.xyzr;
    // Fewer facets for many spheres: SwiftShader and laptops stay interactive at 100k.
    const segments = n <= 2000 ? [32, 20] : n <= 20000 ? [18, 12] : [10, 7];
    const geometry = new THREE.SphereGeometry(1, segments[0], segments[1]);
    const material = new THREE.MeshPhongMaterial({color: 0xffffff, shininess: 30});
    const spheres = new THREE.InstancedMesh(geometry, material, n);
    // three r147 culls an instanced mesh by its one geometry's bounds, not the instances'.
    spheres.frustumCulled = false;
    const matrix = new THREE.Matrix4();
    for (let i = 0; i < n; ++i) {
      const r = xyzr[4 * i + 3];
      matrix.makeScale(r, r, r);
      matrix.setPosition(xyzr[4 * i], xyzr[4 * i + 1], xyzr[4 * i + 2]);
      spheres.setMatrixAt(i, matrix);
    }
    spheres.instanceMatrix.needsUpdate = true;
    return spheres;
  }

  function paintSpheres(spheres, data, mode) {
    const color = new THREE.Color();
    sphereColors(data, mode).forEach((rgb, i) => spheres.setColorAt(i, color.setRGB(...rgb)));
    spheres.instanceColor.needsUpdate = true;
  }

  // Bounds of the mesh and the spheres: centre and radius of the sphere around the box.
  function sceneBounds(data) {
    const box = new THREE.Box3(new THREE.Vector3(...data.mesh.bbox.min),
                               new THREE.Vector3(...data.mesh.bbox.max));
    const xyzr = data.spheres.xyzr;
    for (let i = 0; i < data.spheres.count; ++i) {
      const c = new THREE.Vector3(xyzr[4 * i], xyzr[4 * i + 1], xyzr[4 * i + 2]);
      const r = xyzr[4 * i + 3];
      box.expandByPoint(c.clone().addScalar(r));
      box.expandByPoint(c.addScalar(-r));
    }
    const center = box.getCenter(new THREE.Vector3());
    return {center: center, radius: Math.max(1e-9, box.getSize(new THREE.Vector3()).length() / 2)};
  }

  function main() {
    const data = JSON.parse(document.getElementById('inscribe-data').textContent);
    let options = readOptions();
    const body = document.body;
    const panel = document.getElementById('panel');
    const viewport = document.getElementById('viewport');

    // Panel: heading, report, controls, legend, histograms.
    panel.appendChild(element('h1', {}, data.title));
    panel.appendChild(element('div', {class: 'subtitle'},
                              'inscribe view \u00b7 medial spheres and their quality'));
    panel.appendChild(reportTable(data));
    panel.appendChild(element('h2', {}, 'display'));
    const controls = element('div', {class: 'controls'});
    const meshBox = element('input', {type: 'checkbox', id: 'show-mesh'});
    const spheresBox = element('input', {type: 'checkbox', id: 'show-spheres'});
    const colorSelect = element('select', {id: 'color-by'});
    colorSelect.append(element('option', {value: 'radius'}, 'radius'),
                       element('option', {value: 'protrusion'}, 'protrusion'));
    const meshLabel = element('label', {}, ' mesh');
    meshLabel.prepend(meshBox);
    const spheresLabel = element('label', {}, ' spheres');
    spheresLabel.prepend(spheresBox);
    const colorLabel = element('label', {}, 'colour by ');
    colorLabel.append(colorSelect);
    controls.append(meshLabel, spheresLabel, colorLabel);
    panel.appendChild(controls);
    const legend = element('div', {class: 'legend'});
    const legendCanvas = element('canvas');
    const legendTicks = element('div', {class: 'ticks'});
    legend.append(legendCanvas, legendTicks);
    panel.appendChild(legend);
    const histograms = data.histograms;
    const boundaryCanvas =
        histogramBlock(panel, 'boundary \u2192 envelope', histograms.boundary_to_envelope);
    const envelopeCanvas =
        histogramBlock(panel, 'envelope \u2192 boundary', histograms.envelope_to_boundary);
    panel.appendChild(element(
        'div', {class: 'caption'},
        'Signed distance in mesh units (paper Fig. 7): > 0 where the envelope of the spheres ' +
            'is outside the mesh, < 0 inside. Boundary \u2192 envelope inside a ball is the ' +
            'depth in its deepest ball (a lower bound).'));

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
    headLight.position.set(-0.4, 0.8, 1.0);  // camera frame: from above left, in front
    headLight.target.position.set(0, 0, -1);
    camera.add(headLight, headLight.target);
    const meshObject = buildMesh(data, options);
    const spheres = buildSpheres(data);
    scene.add(spheres, meshObject);
    // Before the controls are made: OrbitControls orbits about the up direction it sees then.
    camera.up.set(...options.up).normalize();
    const controlsOrbit = new THREE.OrbitControls(camera, renderer.domElement);
    const bounds = sceneBounds(data);

    function frame() {
      const width = Math.max(1, viewport.clientWidth);
      const height = Math.max(1, viewport.clientHeight);
      renderer.setSize(width, height);
      camera.aspect = width / height;
      const halfVertical = THREE.MathUtils.degToRad(camera.fov / 2);
      const halfHorizontal = Math.atan(Math.tan(halfVertical) * camera.aspect);
      const distance = 1.04 * bounds.radius / Math.sin(Math.min(halfVertical, halfHorizontal));
      const dir = new THREE.Vector3(...options.dir).normalize();
      camera.position.copy(bounds.center).addScaledVector(dir, distance);
      camera.near = distance / 100;
      camera.far = distance * 10;
      camera.updateProjectionMatrix();
      controlsOrbit.target.copy(bounds.center);
      controlsOrbit.update();
    }

    function render() {
      renderer.render(scene, camera);
      body.dataset.spheresDrawn = String(spheres.visible ? data.spheres.count : 0);
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
      meshBox.checked = options.mesh;
      spheresBox.checked = options.spheres;
      colorSelect.value = options.color;
      meshObject.visible = options.mesh;
      meshObject.material.opacity = options.opacity;
      spheres.visible = options.spheres;
      paintSpheres(spheres, data, options.color);
      drawLegend(legendCanvas, legendTicks, data, options.color);
    }

    meshBox.addEventListener('change', () => {
      options.mesh = meshBox.checked;
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
      options = readOptions();
      apply();
      frame();
      requestRender();
    });
    window.addEventListener('resize', () => {
      const target = controlsOrbit.target.clone();
      const width = Math.max(1, viewport.clientWidth);
      const height = Math.max(1, viewport.clientHeight);
      renderer.setSize(width, height);
      camera.aspect = width / height;
      camera.updateProjectionMatrix();
      controlsOrbit.target.copy(target);
      requestRender();
    });
    controlsOrbit.addEventListener('change', requestRender);

    apply();
    frame();
    drawHistogram(boundaryCanvas, histograms.boundary_to_envelope);
    drawHistogram(envelopeCanvas, histograms.envelope_to_boundary);
    render();
  }

  try {
    main();
  } catch (error) {
    showError(error);
  }
})();
