"""A replay viewer: one self-contained HTML file that plays a saved trajectory.

    python -m ballenv.viewer TRAJ.npz -o replay.html [--max-frames 2000]

``TRAJ.npz`` is a :meth:`ballenv.physics.Trajectory.save` file (the scenes CLI writes them). The
page needs no network and no server: the data is inlined (float32, base64) and drawn on a canvas by
inline JavaScript, in the colours and line widths of the Python renderer (``ballenv.draw.STYLE``,
inlined with the data). It shows the ring(s), the grounds, the ground reaction per node (blue arrows)
and, below, each ring's gauge pressure over time with a cursor; controls: play/pause (space),
a scrub bar, playback speed (0.05x-2x of real time), step buttons (arrow keys). Playback follows the
recorded times, so adaptive-step records play at their true pace.

For tests and scripts: ``#frame=K`` in the URL opens record K; ``window.ballViewer`` has
``setFrame(k)``, ``play()``, ``pause()``, ``frame`` and ``nFrames``; the element ``#status`` carries
``data-frame`` and ``data-t`` (s) of the shown record.
"""

import argparse
import base64
import html
import json
import math
import pathlib
import re
import sys

import numpy as np

from .draw import STYLE
from .files import write_text
from .physics.trajectory import Trajectory


def _b64(array):
    return base64.b64encode(np.ascontiguousarray(array, dtype="<f4").tobytes()).decode("ascii")


def select_frames(t, max_frames):
    """Indices (sorted, unique, first and last kept) of at most ``max_frames`` records of times
    ``t`` (s), evenly spread in time."""
    n = len(t)
    if n <= max_frames:
        return np.arange(n)
    grid = np.linspace(t[0], t[-1], max_frames)
    idx = np.unique(np.clip(np.searchsorted(t, grid), 0, n - 1))
    return np.unique(np.concatenate([[0], idx, [n - 1]]))


def viewer_data(traj, max_frames=2000, title=None):
    """The JSON-ready dict the page plays: records (at most ``max_frames``), grounds, events and
    the drawing style (colours, line width, force scale: :data:`ballenv.draw.STYLE`)."""
    idx = select_frames(traj.t, max_frames)
    scene = traj.scene
    return {
        "title": title or "ballenv trajectory",
        "nFrames": len(idx),
        "nRings": int(traj.x.shape[1]),
        "nNodes": int(traj.x.shape[2]),
        "t": _b64(traj.t[idx]),
        "x": _b64(traj.x[idx]),
        "f": _b64(traj.contact_force[idx]),
        "p": _b64(traj.pressure[idx]),
        "grounds": [
            {"angle": g.angle, "height": g.height, "x": g.x, "friction": g.friction} for g in scene.grounds
        ],
        "drums": [{"centre": list(d.centre), "radius": d.radius, "inside": d.inside} for d in scene.drums],
        "radius": [r.radius for r in scene.rings],
        "events": [[float(t), int(r), k] for t, r, k in traj.events],
        "style": STYLE.as_json(),
        "info": (
            f"{len(scene.rings)} ring(s), N = {scene.rings[0].n_nodes}, {scene.integrator}, "
            f"{traj.stats.steps} steps, {len(traj.t)} records"
            + (f" (showing {len(idx)})" if len(idx) < len(traj.t) else "")
        ),
    }


PAGE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>__TITLE__</title>
<style>
body{font:14px system-ui,sans-serif;margin:12px;background:#fafaf7;color:#222}
#controls{display:flex;gap:8px;align-items:center;margin:6px 0}
#scrub{flex:1}
canvas{background:#fff;border:1px solid #ccc;display:block}
#status{font-family:monospace}
</style></head><body>
<h3 id="title">__TITLE__</h3>
<div id="info"></div>
<canvas id="scene" width="900" height="480"></canvas>
<div id="controls">
<button id="play">play</button>
<button id="back">&#9664;</button><button id="fwd">&#9654;</button>
<input id="scrub" type="range" min="0" max="0" value="0">
<label>speed <select id="speed">
<option value="0.05">0.05x</option><option value="0.1">0.1x</option><option value="0.25" selected>0.25x</option>
<option value="0.5">0.5x</option><option value="1">1x</option><option value="2">2x</option></select></label>
<span id="status" data-frame="-1" data-t="">loading</span>
</div>
<canvas id="plot" width="900" height="160"></canvas>
<script id="data" type="application/json">__DATA__</script>
<script>
"use strict";
(function(){
const D = JSON.parse(document.getElementById("data").textContent);
function f32(s){const b=atob(s);const u=new Uint8Array(b.length);for(let i=0;i<b.length;i++)u[i]=b.charCodeAt(i);return new Float32Array(u.buffer);}
const T=f32(D.t), X=f32(D.x), F=f32(D.f), P=f32(D.p);
const nF=D.nFrames, nR=D.nRings, nN=D.nNodes, per=nR*nN*2;
const S=D.style, COLORS=S.rings;
const cv=document.getElementById("scene"), ctx=cv.getContext("2d");
const pv=document.getElementById("plot"), pctx=pv.getContext("2d");
const scrub=document.getElementById("scrub"), status=document.getElementById("status");
document.getElementById("info").textContent=D.info;
scrub.max=nF-1;
let lo=[Infinity,Infinity], hi=[-Infinity,-Infinity];
for(let i=0;i<X.length;i+=2){lo[0]=Math.min(lo[0],X[i]);hi[0]=Math.max(hi[0],X[i]);lo[1]=Math.min(lo[1],X[i+1]);hi[1]=Math.max(hi[1],X[i+1]);}
const R=Math.max(...D.radius), m=0.6*R;
lo=[lo[0]-m,lo[1]-m]; hi=[hi[0]+m,hi[1]+m];
const span=[hi[0]-lo[0],hi[1]-lo[1]];
const follow = Math.max(span[0],span[1]) > 8*R;
let scale = follow ? cv.height/(5*R) : Math.min(cv.width/span[0], cv.height/span[1]);
let cx=0, cy=0;
function px(x,y){return [cv.width/2+(x-cx)*scale, cv.height/2-(y-cy)*scale];}
const FS=S.force_scale;
let frame=0, playing=false, simTime=T[0], speed=0.25, last=null;
function draw(k){
  frame=k; const o=k*per;
  if(follow){let sx=0,sy=0;for(let i=0;i<per;i+=2){sx+=X[o+i];sy+=X[o+i+1];}cx=sx/(per/2);cy=sy/(per/2);}
  else{cx=(lo[0]+hi[0])/2;cy=(lo[1]+hi[1])/2;}
  ctx.fillStyle=S.background;ctx.fillRect(0,0,cv.width,cv.height);
  const far=10*(cv.width+cv.height)/scale;
  for(const g of D.grounds){
    const n=[-Math.sin(g.angle),Math.cos(g.angle)], d=[Math.cos(g.angle),Math.sin(g.angle)];
    const s=(cx-g.x)*d[0]+(cy-g.height)*d[1]; const b=[g.x+s*d[0], g.height+s*d[1]];
    const q=[[b[0]-far*d[0],b[1]-far*d[1]],[b[0]+far*d[0],b[1]+far*d[1]],[b[0]+far*d[0]-far*n[0],b[1]+far*d[1]-far*n[1]],[b[0]-far*d[0]-far*n[0],b[1]-far*d[1]-far*n[1]]];
    ctx.fillStyle=S.ground;ctx.beginPath();q.forEach((p,i)=>{const c=px(p[0],p[1]);i?ctx.lineTo(c[0],c[1]):ctx.moveTo(c[0],c[1]);});ctx.fill();
  }
  for(const g of D.drums){
    const c=px(g.centre[0],g.centre[1]);ctx.fillStyle=S.ground;ctx.beginPath();
    if(g.inside){ctx.rect(0,0,cv.width,cv.height);}
    ctx.arc(c[0],c[1],g.radius*scale,0,2*Math.PI);ctx.fill("evenodd");
  }
  for(let r=0;r<nR;r++){
    ctx.strokeStyle=COLORS[r%COLORS.length];ctx.lineWidth=S.line_width;ctx.beginPath();
    for(let i=0;i<=nN;i++){const j=o+(r*nN+(i%nN))*2;const c=px(X[j],X[j+1]);i?ctx.lineTo(c[0],c[1]):ctx.moveTo(c[0],c[1]);}
    ctx.stroke();
    ctx.strokeStyle=S.force;ctx.lineWidth=S.line_width;
    for(let i=0;i<nN;i++){const j=o+(r*nN+i)*2;if(F[j]!==0||F[j+1]!==0){const a=px(X[j],X[j+1]),b=px(X[j]+FS*F[j],X[j+1]+FS*F[j+1]);ctx.beginPath();ctx.moveTo(a[0],a[1]);ctx.lineTo(b[0],b[1]);ctx.stroke();}}
  }
  ctx.fillStyle=S.text;ctx.font="14px monospace";
  const ps=[];for(let r=0;r<nR;r++)ps.push((P[k*nR+r]/1e3).toFixed(1));
  ctx.fillText("t = "+T[k].toFixed(4)+" s   p = "+ps.join(", ")+" kPa",8,18);
  scrub.value=k;
  status.dataset.frame=k; status.dataset.t=T[k];
  status.textContent="frame "+k+"/"+(nF-1)+"  t = "+T[k].toFixed(4)+" s";
  drawPlot(k);
}
let pmin=Infinity,pmax=-Infinity;for(const v of P){pmin=Math.min(pmin,v);pmax=Math.max(pmax,v);}
if(pmax-pmin<1){pmax+=1;pmin-=1;}
function tx(t){return 50+(pv.width-60)*(t-T[0])/Math.max(T[nF-1]-T[0],1e-12);}
function py(p){return pv.height-20-(pv.height-35)*(p-pmin)/(pmax-pmin);}
function drawPlot(k){
  pctx.fillStyle="#fff";pctx.fillRect(0,0,pv.width,pv.height);
  pctx.strokeStyle="#999";pctx.strokeRect(50,15,pv.width-60,pv.height-35);
  for(let r=0;r<nR;r++){pctx.strokeStyle=COLORS[r%COLORS.length];pctx.lineWidth=1.2;pctx.beginPath();
    for(let i=0;i<nF;i++){const a=tx(T[i]),b=py(P[i*nR+r]);i?pctx.lineTo(a,b):pctx.moveTo(a,b);}pctx.stroke();}
  pctx.strokeStyle="#000";pctx.beginPath();pctx.moveTo(tx(T[k]),15);pctx.lineTo(tx(T[k]),pv.height-20);pctx.stroke();
  pctx.fillStyle="#222";pctx.font="11px sans-serif";
  pctx.fillText((pmax/1e3).toFixed(1)+" kPa",2,20);pctx.fillText((pmin/1e3).toFixed(1)+" kPa",2,pv.height-20);
  pctx.fillText("gauge pressure over time ("+T[0].toFixed(2)+" - "+T[nF-1].toFixed(2)+" s)",60,pv.height-5);
}
function seek(t){let a=0,b=nF-1;while(a<b){const c=(a+b+1)>>1;if(T[c]<=t)a=c;else b=c-1;}return a;}
function tick(now){
  if(!playing){last=null;return;}
  if(last!==null){simTime+=speed*(now-last)/1000;if(simTime>T[nF-1])simTime=T[0];draw(seek(simTime));}
  last=now;requestAnimationFrame(tick);
}
const btn=document.getElementById("play");
function play(){if(!playing){playing=true;btn.textContent="pause";simTime=T[frame];requestAnimationFrame(tick);}}
function pause(){playing=false;btn.textContent="play";}
btn.onclick=()=>playing?pause():play();
scrub.oninput=()=>{pause();draw(+scrub.value);};
document.getElementById("speed").onchange=e=>{speed=+e.target.value;};
document.getElementById("back").onclick=()=>{pause();draw(Math.max(0,frame-1));};
document.getElementById("fwd").onclick=()=>{pause();draw(Math.min(nF-1,frame+1));};
pv.onclick=e=>{pause();const r=pv.getBoundingClientRect();const t=T[0]+(e.clientX-r.left-50)/(pv.width-60)*(T[nF-1]-T[0]);draw(seek(t));};
document.addEventListener("keydown",e=>{if(e.key===" "){e.preventDefault();playing?pause():play();}
  else if(e.key==="ArrowRight"){pause();draw(Math.min(nF-1,frame+1));}else if(e.key==="ArrowLeft"){pause();draw(Math.max(0,frame-1));}});
window.ballViewer={setFrame:k=>draw(Math.max(0,Math.min(nF-1,k|0))),play,pause,get frame(){return frame;},nFrames:nF};
const h=/frame=(\\d+)/.exec(location.hash);
draw(h?Math.min(nF-1,+h[1]):0);
})();
</script></body></html>
"""


def write_html(traj, path, max_frames=2000, title=None):
    """Write the replay page of ``traj`` (a :class:`Trajectory`) to ``path``; returns the path."""
    if not isinstance(max_frames, int) or max_frames < 2:
        raise ValueError(f"write_html.max_frames = {max_frames!r} is out of range: must be an integer >= 2")
    data = viewer_data(traj, max_frames, title)
    return write_text(path, page(data))


# JSON inside <script type="application/json">: the characters that could end the element, open a
# comment or a new tag, or start an entity are escaped (JSON reads them back unchanged)
SCRIPT_ESCAPES = {ord("<"): "\\u003c", ord(">"): "\\u003e", ord("&"): "\\u0026"}


def page(data):
    """The HTML page of ``data`` (:func:`viewer_data`): the title HTML-escaped, the data as JSON with
    ``<``, ``>`` and ``&`` escaped, both put in one pass over the template (a placeholder inside the
    title or the data is text, never a place to fill)."""
    fills = {
        "__TITLE__": html.escape(str(data["title"])),
        "__DATA__": json.dumps(data).translate(SCRIPT_ESCAPES),
    }
    return re.sub("__TITLE__|__DATA__", lambda m: fills[m.group(0)], PAGE)


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="python -m ballenv.viewer",
        description="Write a self-contained HTML page that replays a saved trajectory (.npz).",
    )
    parser.add_argument("trajectory", help="a Trajectory.save file (.npz)")
    parser.add_argument("-o", "--out", default="replay.html", help="HTML file to write (default replay.html)")
    parser.add_argument(
        "--max-frames", type=int, default=2000, help="records kept, evenly in time (default 2000)"
    )
    parser.add_argument("--title", default=None, help="page title (default: the file name)")
    args = parser.parse_args(argv)
    try:
        traj = Trajectory.load(args.trajectory)
    except (FileNotFoundError, ValueError) as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    path = write_html(traj, args.out, args.max_frames, args.title or pathlib.Path(args.trajectory).name)
    size = path.stat().st_size
    print(
        f"wrote {path} ({size / 1e6:.2f} MB, {math.ceil(min(len(traj.t), args.max_frames))} records at most)"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
