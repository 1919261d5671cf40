//! The self-contained 3D page of a motion (`fold.html`, `nanofold view`): the frames'
//! coordinates and the sheet's faces and edges as JSON inside one HTML file, drawn by a
//! small canvas renderer of its own (painter's order, both sides shaded apart), with orbit,
//! pan and zoom, a frame slider with play and speed, a scale bar and the fold angle of a
//! selected crease. No request leaves the page.

use crate::error::{NanofoldError, Result};
use serde_json::json;

/// Most frames × vertices one page holds (about 25 MB of coordinates at the limit).
pub const MAX_PAGE_POINTS: usize = 4_000_000;

/// One frame of a page.
#[derive(Debug, Clone, PartialEq)]
pub struct PageFrame {
    /// Shown beside the slider (progress, time).
    pub title: String,
    /// Every vertex's position, in the scene's units.
    pub coords: Vec<[f64; 3]>,
    /// Every edge's fold angle in degrees, where known.
    pub fold_angles_deg: Option<Vec<f64>>,
    /// Faces to highlight (the panels of a first contact).
    pub highlight: Vec<usize>,
}

/// What a page shows.
#[derive(Debug, Clone, PartialEq)]
pub struct PageScene {
    /// The page's title.
    pub title: String,
    /// The length unit, for the scale bar.
    pub unit: String,
    /// Faces as vertex loops.
    pub faces: Vec<Vec<usize>>,
    /// Edges as vertex pairs.
    pub edges: Vec<[usize; 2]>,
    /// FOLD assignment letter of each edge (M, V, B, F, U, C, J).
    pub assignments: Vec<char>,
    /// The frames, at least one.
    pub frames: Vec<PageFrame>,
    /// Faces that do not move (the substrate, the anchored panel), drawn grey.
    pub fixed: Vec<usize>,
}

impl PageScene {
    /// The scene with every coordinate multiplied by `factor` and the scale bar in `unit`
    /// (a device's metres shown in µm).
    pub fn scaled(mut self, factor: f64, unit: &str) -> Self {
        for p in self.frames.iter_mut().flat_map(|f| f.coords.iter_mut()) {
            p.iter_mut().for_each(|x| *x *= factor);
        }
        self.unit = unit.to_string();
        self
    }
}

/// Coordinates are written as integers of this fraction of the scene's half-size.
const QUANTUM: f64 = 1e-5;

/// The page as one HTML document. Refuses a scene without frames or faces, with indices out
/// of range, non-finite coordinates, or more than [`MAX_PAGE_POINTS`] points.
pub fn page_html(scene: &PageScene) -> Result<String> {
    let vertices = scene.frames.first().map_or(0, |f| f.coords.len());
    if scene.frames.is_empty() || vertices == 0 {
        return Err(NanofoldError::invalid(
            "frames",
            0,
            "a page needs a frame with vertices",
        ));
    }
    if scene.frames.len().saturating_mul(vertices) > MAX_PAGE_POINTS {
        return Err(NanofoldError::invalid(
            "frames",
            format!("{} frames of {vertices} vertices", scene.frames.len()),
            format!("a page holds at most {MAX_PAGE_POINTS} points: ask for fewer frames"),
        ));
    }
    for (k, frame) in scene.frames.iter().enumerate() {
        if frame.coords.len() != vertices {
            return Err(NanofoldError::invalid(
                format!("frames[{k}].coords"),
                frame.coords.len(),
                format!("every frame has the first frame's {vertices} vertices"),
            ));
        }
        if frame.coords.iter().flatten().any(|x| !x.is_finite()) {
            return Err(NanofoldError::invalid(
                format!("frames[{k}].coords"),
                "non-finite",
                "finite coordinates",
            ));
        }
    }
    if let Some(bad) = scene
        .faces
        .iter()
        .flatten()
        .chain(scene.edges.iter().flatten())
        .find(|&&v| v >= vertices)
    {
        return Err(NanofoldError::invalid(
            "faces/edges",
            bad,
            format!("vertex indices below {vertices}"),
        ));
    }
    if let Some(bad) = scene
        .frames
        .iter()
        .flat_map(|f| &f.highlight)
        .chain(&scene.fixed)
        .find(|&&f| f >= scene.faces.len())
    {
        return Err(NanofoldError::invalid(
            "highlight/fixed",
            bad,
            format!("face indices below {}", scene.faces.len()),
        ));
    }
    // Centre and half-size over every frame, so the quantised integers stay small.
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in scene.frames.iter().flat_map(|f| &f.coords) {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let centre = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])];
    let half = (0..3)
        .map(|k| 0.5 * (hi[k] - lo[k]))
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    let step = half * QUANTUM;
    let frames: Vec<_> = scene
        .frames
        .iter()
        .map(|f| {
            let q: Vec<i64> = f
                .coords
                .iter()
                .flat_map(|p| (0..3).map(move |k| ((p[k] - centre[k]) / step).round() as i64))
                .collect();
            json!({
                "t": f.title,
                "q": q,
                "a": f.fold_angles_deg.as_ref().map(|a| a.iter().map(|x| (x * 1e3).round() / 1e3).collect::<Vec<_>>()),
                "h": f.highlight,
            })
        })
        .collect();
    let data = json!({
        "title": scene.title,
        "unit": scene.unit,
        "step": step,
        "half": half,
        "faces": scene.faces,
        "edges": scene.edges,
        "letters": scene.assignments.iter().collect::<String>(),
        "fixed": scene.fixed,
        "frames": frames,
    });
    // Inside <script>, "</" would end the element.
    let data = data.to_string().replace("</", "<\\/");
    let title = escape(&scene.title);
    Ok(PAGE.replace("{{TITLE}}", &title).replace("{{DATA}}", &data))
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

const PAGE: &str = r##"<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{{TITLE}}</title>
<style>
html,body{margin:0;height:100%;font:13px system-ui,sans-serif;background:#fafafa;color:#222}
#view{position:absolute;inset:0 0 64px 0;width:100%;height:calc(100% - 64px);touch-action:none;cursor:grab}
#bar{position:absolute;left:0;right:0;bottom:0;height:64px;padding:6px 10px;box-sizing:border-box;background:#eee;border-top:1px solid #ccc}
#bar input[type=range]{width:calc(100% - 330px);vertical-align:middle}
#info{position:absolute;top:8px;left:10px;background:#ffffffd0;padding:4px 8px;border-radius:4px;max-width:60%}
#legend{position:absolute;top:8px;right:10px;background:#ffffffd0;padding:4px 8px;border-radius:4px}
.sw{display:inline-block;width:18px;height:3px;vertical-align:middle;margin:0 3px 0 8px}
</style></head><body>
<canvas id="view"></canvas>
<div id="info"><b id="title"></b><br><span id="frame"></span><br><span id="crease">click a crease for its fold angle</span></div>
<div id="legend"><span class="sw" style="background:#d33"></span>mountain<span class="sw" style="background:#36c"></span>valley<span class="sw" style="background:#222"></span>boundary
<br><label><input type="checkbox" id="bysign"> colour creases by their current sign</label></div>
<div id="bar"><button id="play">play</button>
<select id="speed"><option value="0.25">¼×</option><option value="0.5">½×</option><option value="1" selected>1×</option><option value="2">2×</option><option value="4">4×</option></select>
<input type="range" id="slider" min="0" value="0" step="1"> <span id="count"></span>
<br><small>drag: turn · shift-drag or two fingers: pan · wheel or pinch: zoom · double-click: reset</small></div>
<script type="application/json" id="data">{{DATA}}</script>
<script>
"use strict";
const D=JSON.parse(document.getElementById("data").textContent);
const canvas=document.getElementById("view"),ctx=canvas.getContext("2d");
const slider=document.getElementById("slider"),play=document.getElementById("play");
const F=D.frames.length,NV=D.frames[0].q.length/3;
slider.max=F-1;
document.getElementById("title").textContent=D.title;
const edgeOf=new Map();D.edges.forEach((e,i)=>{edgeOf.set(e[0]+","+e[1],i);edgeOf.set(e[1]+","+e[0],i);});
const fixed=new Set(D.fixed||[]);
if(fixed.size)document.getElementById("legend").insertAdjacentHTML("beforeend","<br><span class=\"sw\" style=\"background:#bbb;height:10px\"></span>grey: fixed (substrate, anchored panel)");
const faceEdges=D.faces.map(f=>f.map((v,k)=>edgeOf.get(v+","+f[(k+1)%f.length])).filter(i=>i!==undefined));
let yaw=-0.6,pitch=0.9,zoom=1,panX=0,panY=0,frame=0,playing=false,selected=-1,last=0,acc=0;
function reset(){yaw=-0.6;pitch=0.9;zoom=1;panX=0;panY=0;}
function coords(k){const q=D.frames[k].q,s=D.step,out=new Float64Array(q.length);for(let i=0;i<q.length;i++)out[i]=q[i]*s;return out;}
let cache=new Map();function pos(k){if(!cache.has(k)){if(cache.size>64)cache.clear();cache.set(k,coords(k));}return cache.get(k);}
function size(){const r=canvas.getBoundingClientRect(),d=window.devicePixelRatio||1;canvas.width=Math.max(1,r.width*d);canvas.height=Math.max(1,r.height*d);ctx.setTransform(d,0,0,d,0,0);return r;}
function project(p,r){const cy=Math.cos(yaw),sy=Math.sin(yaw),cp=Math.cos(pitch),sp=Math.sin(pitch),n=p.length/3;
 const s=0.42*Math.min(r.width,r.height)/D.half*zoom,out=new Float64Array(n*3);
 for(let i=0;i<n;i++){const x=p[3*i],y=p[3*i+1],z=p[3*i+2];const x1=cy*x-sy*y,y1=sy*x+cy*y;const y2=cp*y1-sp*z,z2=sp*y1+cp*z;
  out[3*i]=r.width/2+panX+s*x1;out[3*i+1]=r.height/2+panY-s*z2;out[3*i+2]=y2;}return [out,s];}
function colour(i,a){const L=D.letters[i];if(document.getElementById("bysign").checked&&a){const v=a[i];if(Math.abs(v)<1e-9)return "#999";return v<0?"#d33":"#36c";}
 return L==="M"?"#d33":L==="V"?"#36c":L==="B"?"#222":"#999";}
function draw(){const r=size();ctx.clearRect(0,0,r.width,r.height);const fr=D.frames[frame];const[P,s]=project(pos(frame),r);
 const order=D.faces.map((f,i)=>{let d=0;for(const v of f)d+=P[3*v+2];return[d/f.length,i];}).sort((a,b)=>b[0]-a[0]);
 const hl=new Set(fr.h||[]);
 for(const[,i]of order){const f=D.faces[i];ctx.beginPath();ctx.moveTo(P[3*f[0]],P[3*f[0]+1]);for(let k=1;k<f.length;k++)ctx.lineTo(P[3*f[k]],P[3*f[k]+1]);ctx.closePath();
  let area=0;for(let k=0;k<f.length;k++){const a=f[k],b=f[(k+1)%f.length];area+=P[3*a]*P[3*b+1]-P[3*b]*P[3*a+1];}
  ctx.fillStyle=hl.has(i)?"#f66":fixed.has(i)?(area<0?"#c4c4c4":"#b0b0b0"):(area<0?"#f3d38a":"#9dbde0");ctx.fill();ctx.lineWidth=0.5;ctx.strokeStyle="#0003";ctx.stroke();
  for(const e of faceEdges[i]){const[a,b]=D.edges[e];ctx.beginPath();ctx.moveTo(P[3*a],P[3*a+1]);ctx.lineTo(P[3*b],P[3*b+1]);ctx.strokeStyle=e===selected?"#0c0":colour(e,fr.a);ctx.lineWidth=e===selected?3:1.5;ctx.stroke();}}
 // Scale bar: a round length near 100 px.
 const target=100/s,pow=Math.pow(10,Math.floor(Math.log10(target)));let len=pow;for(const m of[1,2,5,10])if(m*pow<=target)len=m*pow;
 ctx.strokeStyle="#222";ctx.lineWidth=2;ctx.beginPath();ctx.moveTo(16,r.height-16);ctx.lineTo(16+len*s,r.height-16);ctx.stroke();
 ctx.fillStyle="#222";ctx.fillText(+len.toPrecision(3)+" "+D.unit,16,r.height-22);
 document.getElementById("frame").textContent=fr.t;document.getElementById("count").textContent=(frame+1)+" / "+F;
 if(selected>=0){const a=fr.a?(fr.a[selected]).toFixed(3)+"°":"(no fold angle in this file)";document.getElementById("crease").textContent="edge "+selected+" ("+D.letters[selected]+"): "+a;}
 // What was painted, for a headless browser's check (pixels off the background, a hash).
 const img=ctx.getImageData(0,0,canvas.width,canvas.height).data;let painted=0,hash=0;
 for(let i=0;i<img.length;i+=4){if(img[i+3]>0)painted++;hash=(hash*31+img[i]+7*img[i+1]+13*img[i+2])|0;}
 const root=document.documentElement.dataset;root.painted=painted;root.hash=hash;root.frame=frame;root.highlighted=order.filter(([,i])=>hl.has(i)).length;root.draws=(+(root.draws||0))+1;}
slider.oninput=()=>{frame=+slider.value;draw();};
play.onclick=()=>{playing=!playing;play.textContent=playing?"pause":"play";last=performance.now();acc=0;if(playing)requestAnimationFrame(tick);};
function tick(now){if(!playing)return;acc+=(now-last)/1000*10*(+document.getElementById("speed").value);last=now;
 if(acc>=1){frame=(frame+Math.floor(acc))%F;acc%=1;slider.value=frame;draw();}requestAnimationFrame(tick);}
document.getElementById("bysign").onchange=draw;
const pointers=new Map();let pinch=0,moved=false;
canvas.onpointerdown=e=>{canvas.setPointerCapture(e.pointerId);pointers.set(e.pointerId,[e.clientX,e.clientY]);moved=false;};
canvas.onpointermove=e=>{if(!pointers.has(e.pointerId))return;const[px,py]=pointers.get(e.pointerId);const dx=e.clientX-px,dy=e.clientY-py;
 if(Math.abs(dx)+Math.abs(dy)>2)moved=true;
 if(pointers.size===2){const o=[...pointers.entries()].find(([k])=>k!==e.pointerId)[1];const d0=Math.hypot(px-o[0],py-o[1]),d1=Math.hypot(e.clientX-o[0],e.clientY-o[1]);
  if(d0>0)zoom*=d1/d0;panX+=dx/2;panY+=dy/2;}
 else if(e.shiftKey||e.buttons===4||e.buttons===2){panX+=dx;panY+=dy;}
 else{yaw+=dx*0.01;pitch=Math.max(-3.1,Math.min(3.1,pitch+dy*0.01));}
 pointers.set(e.pointerId,[e.clientX,e.clientY]);draw();};
canvas.onpointerup=e=>{pointers.delete(e.pointerId);if(!moved)pick(e);};
canvas.oncontextmenu=e=>e.preventDefault();
canvas.onwheel=e=>{e.preventDefault();zoom*=Math.exp(-e.deltaY*0.001);draw();};
canvas.ondblclick=()=>{reset();draw();};
function pick(e){const r=canvas.getBoundingClientRect(),x=e.clientX-r.left,y=e.clientY-r.top;const[P]=project(pos(frame),r);let best=8,found=-1;
 D.edges.forEach(([a,b],i)=>{if(D.letters[i]==="B")return;const ax=P[3*a],ay=P[3*a+1],bx=P[3*b],by=P[3*b+1];const L=(bx-ax)**2+(by-ay)**2;
  const t=L>0?Math.max(0,Math.min(1,((x-ax)*(bx-ax)+(y-ay)*(by-ay))/L)):0;const d=Math.hypot(x-ax-t*(bx-ax),y-ay-t*(by-ay));if(d<best){best=d;found=i;}});
 selected=found;if(found<0)document.getElementById("crease").textContent="click a crease for its fold angle";draw();}
window.onresize=draw;
// #frame=N opens at frame N (the browser test and links use it).
const m=location.hash.match(/frame=(\d+)/);if(m){frame=Math.min(F-1,+m[1]);slider.value=frame;}
draw();
</script></body></html>
"##;

/// A page of states of a crease pattern: each (title, fold angles) placed by the spanning
/// tree, the pattern's faces and edges, assignments from the file.
pub fn page_of_states(
    model: &crate::folding::FoldingModel,
    title: &str,
    states: &[(String, &[f64])],
) -> Result<String> {
    let pattern = &model.pattern;
    let mut poses = Vec::new();
    let frames = states
        .iter()
        .map(|(label, fold_angles)| {
            crate::folding::panel_poses(model, fold_angles, &mut poses);
            let mut angles = vec![0.0; pattern.edges.len()];
            for (column, &e) in pattern.creases.iter().enumerate() {
                angles[e] = fold_angles[column].to_degrees();
            }
            PageFrame {
                title: label.clone(),
                coords: crate::folding::vertex_positions(model, &poses),
                fold_angles_deg: Some(angles),
                highlight: Vec::new(),
            }
        })
        .collect();
    page_html(&PageScene {
        title: title.to_string(),
        unit: pattern.unit.clone().unwrap_or_else(|| "(file units)".into()),
        faces: pattern.faces.clone(),
        edges: pattern.edges.clone(),
        assignments: pattern.kinds.iter().map(|&k| letter(k)).collect(),
        frames,
        fixed: Vec::new(),
    })
}

fn letter(kind: crate::pattern::crease_pattern::EdgeKind) -> char {
    use crate::pattern::crease_pattern::EdgeKind;
    use crate::pattern::Assignment;
    match kind {
        EdgeKind::Boundary => 'B',
        EdgeKind::Facet => 'F',
        EdgeKind::Crease(Assignment::Mountain) => 'M',
        EdgeKind::Crease(Assignment::Valley) => 'V',
        EdgeKind::Crease(Assignment::Flat) => 'F',
        EdgeKind::Crease(Assignment::Unassigned) => 'U',
    }
}

/// A page of a FOLD object as another tool wrote it: its key frame and its `file_frames`
/// (a frame without `vertices_coords` or `faces_vertices` takes its parent's), 2D
/// coordinates at z = 0, `edges_foldAngle` shown where given; `last_highlight` faces are
/// marked in the last frame (a first contact); `scale` = (length of one file unit, its
/// name) shows the scene in physical units (a device's µm). Errors name the field.
pub fn page_of_fold(
    value: &serde_json::Value,
    name: &str,
    last_highlight: &[usize],
    scale: Option<(f64, &str)>,
) -> Result<String> {
    let mut scene = scene_of_fold(value, name)?;
    if let Some(last) = scene.frames.last_mut() {
        last.highlight = last_highlight.to_vec();
    }
    if let Some((factor, unit)) = scale {
        scene = scene.scaled(factor, unit);
    }
    page_html(&scene)
}

/// The [`PageScene`] of a FOLD object (see [`page_of_fold`]), for callers that add fixed
/// faces or highlights before writing it.
pub fn scene_of_fold(value: &serde_json::Value, name: &str) -> Result<PageScene> {
    use serde_json::Value;
    let field = |frame: &Value, key: &str| -> Option<Value> { frame.get(key).cloned() };
    let key_frame = value;
    let mut frames_json: Vec<&Value> = vec![key_frame];
    if let Some(Value::Array(list)) = value.get("file_frames") {
        frames_json.extend(list.iter());
    }
    let pick = |frame: &Value, key: &str| field(frame, key).or_else(|| field(key_frame, key));
    let edges: Vec<[usize; 2]> = pick(key_frame, "edges_vertices")
        .and_then(|v| serde_json::from_value(v).ok())
        .ok_or_else(|| {
            NanofoldError::invalid(
                "edges_vertices",
                "missing or not pairs of indices",
                "a FOLD file's edges",
            )
        })?;
    let faces: Vec<Vec<usize>> = pick(key_frame, "faces_vertices")
        .and_then(|v| serde_json::from_value(v).ok())
        .ok_or_else(|| {
            NanofoldError::invalid(
                "faces_vertices",
                "missing",
                "a page draws faces: give faces_vertices (a crease pattern without them is drawn from its own faces by `nanofold view` on the crease pattern)",
            )
        })?;
    let letters: Vec<char> = pick(key_frame, "edges_assignment")
        .and_then(|v| serde_json::from_value::<Vec<String>>(v).ok())
        .map(|l| {
            l.iter()
                .map(|s| s.chars().next().unwrap_or('U').to_ascii_uppercase())
                .collect()
        })
        .unwrap_or_else(|| vec!['U'; edges.len()]);
    if letters.len() != edges.len() {
        return Err(NanofoldError::invalid(
            "edges_assignment",
            letters.len(),
            format!("one per edge ({})", edges.len()),
        ));
    }
    let mut frames = Vec::new();
    for (k, frame) in frames_json.iter().enumerate() {
        let coords: Vec<Vec<f64>> = pick(frame, "vertices_coords")
            .and_then(|v| serde_json::from_value(v).ok())
            .ok_or_else(|| {
                NanofoldError::invalid(
                    if k == 0 {
                        "vertices_coords".to_string()
                    } else {
                        format!("file_frames[{}].vertices_coords", k - 1)
                    },
                    "missing or not numbers",
                    "coordinates for every frame",
                )
            })?;
        let coords: Vec<[f64; 3]> = coords
            .iter()
            .map(|p| {
                [
                    p.first().copied().unwrap_or(0.0),
                    p.get(1).copied().unwrap_or(0.0),
                    p.get(2).copied().unwrap_or(0.0),
                ]
            })
            .collect();
        let angles: Option<Vec<f64>> = field(frame, "edges_foldAngle").and_then(|v| serde_json::from_value(v).ok());
        let title = field(frame, "frame_title")
            .and_then(|v| v.as_str().map(String::from))
            .unwrap_or_else(|| format!("frame {k}"));
        frames.push(PageFrame {
            title,
            coords,
            fold_angles_deg: angles.filter(|a| a.len() == edges.len()),
            highlight: Vec::new(),
        });
    }
    // A crease pattern's key frame (2D) before 3D frames is the flat sheet: keep it only
    // where it is the sole frame.
    if frames.len() > 1 && frames[0].coords.iter().all(|p| p[2] == 0.0) {
        frames.remove(0);
    }
    let vertices = frames[0].coords.len();
    frames.retain(|f| f.coords.len() == vertices);
    Ok(PageScene {
        title: value
            .get("file_title")
            .and_then(|v| v.as_str())
            .unwrap_or(name)
            .to_string(),
        unit: value
            .get("frame_unit")
            .and_then(|v| v.as_str())
            .unwrap_or("(file units)")
            .to_string(),
        faces,
        edges,
        assignments: letters,
        frames,
        fixed: Vec::new(),
    })
}
