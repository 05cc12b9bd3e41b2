# Writes the nibabel_* NIfTI fixtures and nibabel_expected.txt (nibabel 5.4.2, numpy).
# Run from crates/biotet-io/tests/data:  python nibabel_grids.py
import numpy as np, nibabel as nib
from nibabel.nifti2 import Nifti2Header

def rot(u, a):
    u = np.asarray(u, float); u /= np.linalg.norm(u)
    x, y, z = u; s, c = np.sin(a), np.cos(a); t = 1 - c
    return np.array([[t*x*x+c, t*x*y-s*z, t*x*z+s*y],
                     [t*x*y+s*z, t*y*y+c, t*y*z-s*x],
                     [t*x*z-s*y, t*y*z+s*x, t*z*z+c]])

i, j, k = np.meshgrid(np.arange(5), np.arange(4), np.arange(3), indexing="ij")
f = 1 + 0.5 * i - 0.25 * j + 2 * k          # shape (5, 4, 3); x varies fastest on disk
A = np.eye(4)
A[:3, :3] = rot([1, 2, 3], 0.5) @ np.diag([0.8, 1.1, 2.5])
A[:3, 3] = [-20, 5.5, 13]

# 1. int16 with nibabel's own scl_slope/scl_inter, sform (code 2), gzipped.
img = nib.Nifti1Image(f, A)
img.set_data_dtype(np.int16)
nib.save(img, "nibabel_int16_sform.nii.gz")

# 2. float32, qform only (code 1) of a reflection: qfac = pixdim[0] = -1.
B = A.copy(); B[:3, 2] *= -1
img = nib.Nifti1Image(f.astype(np.float32), None)
img.set_qform(B, code=1)
img.set_sform(None, code=0)
nib.save(img, "nibabel_qform_flipped.nii")

# 3. NIfTI-2, float64, big-endian, sform.
img = nib.Nifti2Image(f, A, header=Nifti2Header(endianness=">"))
img.set_data_dtype(">f8")
nib.save(img, "nibabel_nifti2_bigendian.nii")

# What nibabel reads back: the affine (3 rows of 4) and the values (x fastest).
with open("nibabel_expected.txt", "w") as out:
    for n in ["nibabel_int16_sform.nii.gz", "nibabel_qform_flipped.nii", "nibabel_nifti2_bigendian.nii"]:
        im = nib.load(n)
        out.write(n + "\n")
        out.write(" ".join(repr(float(x)) for x in im.affine[:3].ravel()) + "\n")
        out.write(" ".join(repr(float(x)) for x in im.get_fdata().ravel(order="F")) + "\n")
