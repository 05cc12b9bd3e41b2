# Writes the label_* fixtures and label_expected.txt: the same 5x4x3 label volume in every
# label image format biotet reads, written by the formats' own tools (nibabel 5.4.2, pynrrd,
# SimpleITK; the .vti by hand, ascii). Run from crates/biotet-io/tests/data:
#   python label_images.py
import numpy as np, nibabel as nib, nrrd, SimpleITK as sitk
from nibabel.nifti2 import Nifti2Image

def rot(u, a):
    u = np.asarray(u, float); u /= np.linalg.norm(u)
    x, y, z = u; s, c = np.sin(a), np.cos(a); t = 1 - c
    return np.array([[t*x*x+c, t*x*y-s*z, t*x*z+s*y],
                     [t*x*y+s*z, t*y*y+c, t*y*z-s*x],
                     [t*x*z-s*y, t*y*z+s*x, t*z*z+c]])

i, j, k = np.meshgrid(np.arange(5), np.arange(4), np.arange(3), indexing="ij")
lab = ((i + 2 * j + 3 * k) % 4).astype(np.int32)
lab[lab == 3] = 41          # FreeSurfer-like values
lab[4, 3, 2] = 17
A = np.eye(4)
A[:3, :3] = rot([1, 2, 3], 0.5) @ np.diag([0.8, 1.1, 2.5])
A[:3, 3] = [-20, 5.5, 13]
out = []

def note(name, affine):
    out.append(name + " " + " ".join(repr(float(x)) for x in np.asarray(affine)[:3].ravel()))

# NIfTI-1 int16 sform (gzipped), NIfTI-2 float32 qform-only, uint8.
img = nib.Nifti1Image(lab.astype(np.int16), A); nib.save(img, "label_nifti1_int16.nii.gz")
note("label_nifti1_int16.nii.gz", nib.load("label_nifti1_int16.nii.gz").affine)
img = Nifti2Image(lab.astype(np.float32), None); img.set_qform(A, code=1); img.set_sform(None, code=0)
nib.save(img, "label_nifti2_float32_qform.nii")
note("label_nifti2_float32_qform.nii", nib.load("label_nifti2_float32_qform.nii").affine)
# A fractional label: refused.
bad = lab.astype(np.float32); bad[1, 1, 1] = 2.5
nib.save(nib.Nifti1Image(bad, A), "label_fractional.nii")

# MGH (gzipped), uint8.
img = nib.MGHImage(lab.astype(np.uint8), A); nib.save(img, "label_uint8.mgz")
note("label_uint8.mgz", nib.load("label_uint8.mgz").affine)

# NRRD: LPS, gzip, int16 (the layout Slicer writes); RAS, detached raw, big-endian uint16.
L = np.diag([-1, -1, 1, 1]) @ A
nrrd.write("label_lps_gzip.nrrd", lab.astype(np.int16), {
    "space": "left-posterior-superior", "space directions": L[:3, :3].T,
    "space origin": L[:3, 3], "encoding": "gzip"})
nrrd.write("label_ras_detached.nhdr", lab.astype(np.uint16), {
    "space": "right-anterior-superior", "space directions": A[:3, :3].T,
    "space origin": A[:3, 3], "encoding": "raw", "endian": "big"}, detached_header=True)

# MetaImage (ITK: LPS): compressed .mha uint8, uncompressed .mhd + .raw int32.
def itk(arr):
    im = sitk.GetImageFromArray(np.ascontiguousarray(arr.transpose(2, 1, 0)))
    sp = np.linalg.norm(L[:3, :3], axis=0)
    im.SetSpacing(sp.tolist()); im.SetOrigin(L[:3, 3].tolist())
    im.SetDirection((L[:3, :3] / sp).ravel().tolist())
    return im
sitk.WriteImage(itk(lab.astype(np.uint8)), "label_uint8.mha", True)
sitk.WriteImage(itk(lab.astype(np.int32)), "label_int32.mhd", False)

# VTK ImageData, ascii, with Direction (taken as RAS).
sp = np.linalg.norm(A[:3, :3], axis=0); D = A[:3, :3] / sp
vals = " ".join(str(int(v)) for v in lab.transpose(2, 1, 0).ravel())
with open("label_ascii.vti", "w") as fh:
    fh.write(f'''<?xml version="1.0"?>
<VTKFile type="ImageData" version="1.0" byte_order="LittleEndian">
  <ImageData WholeExtent="0 4 0 3 0 2" Origin="{' '.join(map(repr, A[:3, 3].tolist()))}" Spacing="{' '.join(map(repr, sp.tolist()))}" Direction="{' '.join(map(repr, D.ravel().tolist()))}">
    <Piece Extent="0 4 0 3 0 2">
      <PointData Scalars="labels">
        <DataArray type="Int32" Name="labels" format="ascii">{vals}</DataArray>
      </PointData>
    </Piece>
  </ImageData>
</VTKFile>
''')

with open("label_expected.txt", "w") as fh:
    fh.write("# nibabel's affine (3 rows) of the NIfTI and MGH files; every label_* file holds\n")
    fh.write("# this affine (RAS) and the labels below, i fastest\n")
    fh.write("affine " + " ".join(repr(float(x)) for x in A[:3].ravel()) + "\n")
    for line in out:
        fh.write(line + "\n")
    fh.write("labels " + " ".join(str(int(v)) for v in lab.transpose(2, 1, 0).ravel()) + "\n")
