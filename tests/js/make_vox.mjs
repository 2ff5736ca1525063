// Writes a small MagicaVoxel file (a coloured ball with a hole through it)
// for the glTF validator test: node make_vox.mjs OUT.vox
import fs from 'node:fs';

const le = (v) => { const b = Buffer.alloc(4); b.writeInt32LE(v); return b; };
const chunk = (id, content, children = Buffer.alloc(0)) =>
  Buffer.concat([Buffer.from(id), le(content.length), le(children.length), content, children]);
const voxels = [];
for (let x = 0; x < 12; ++x)
  for (let y = 0; y < 12; ++y)
    for (let z = 0; z < 12; ++z) {
      const r2 = (x - 5.5) ** 2 + (y - 5.5) ** 2 + (z - 5.5) ** 2;
      if (r2 < 30 && !((x - 5.5) ** 2 + (y - 5.5) ** 2 < 3)) voxels.push([x, y, z, 1 + ((x + 2 * z) % 7) * 30]);
    }
const xyzi = Buffer.concat([le(voxels.length), Buffer.from(voxels.flat())]);
const main = Buffer.concat([chunk('SIZE', Buffer.concat([le(12), le(12), le(12)])), chunk('XYZI', xyzi)]);
fs.writeFileSync(process.argv[2], Buffer.concat([Buffer.from('VOX '), le(150), chunk('MAIN', Buffer.alloc(0), main)]));
