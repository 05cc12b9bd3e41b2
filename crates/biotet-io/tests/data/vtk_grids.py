# Writes the vtk_image_*.vti fixtures (VTK 9, vtkXMLImageDataWriter).
# Run from crates/biotet-io/tests/data:  python vtk_grids.py
import math
import vtk

def rot(u, a):
    n = math.sqrt(sum(c * c for c in u)); x, y, z = (c / n for c in u)
    s, c = math.sin(a), math.cos(a); t = 1 - c
    return [t*x*x+c, t*x*y-s*z, t*x*z+s*y,
            t*x*y+s*z, t*y*y+c, t*y*z-s*x,
            t*x*z-s*y, t*y*z+s*x, t*z*z+c]

def f(p):
    return 1 + 0.5 * p[0] - 0.25 * p[1] + 2 * p[2]

img = vtk.vtkImageData()
img.SetExtent(1, 5, -2, 1, 0, 2)             # 5 x 4 x 3 points, not starting at 0
img.SetOrigin(-20, 5.5, 13)
img.SetSpacing(0.8, 1.1, 2.5)
img.SetDirectionMatrix(rot([1, 2, 3], 0.5))
other = vtk.vtkShortArray(); other.SetName("other")
size = vtk.vtkDoubleArray(); size.SetName("size")
for i in range(img.GetNumberOfPoints()):
    other.InsertNextValue(7)
    size.InsertNextValue(f(img.GetPoint(i)))
img.GetPointData().AddArray(other)
img.GetPointData().SetScalars(size)           # the active scalars, after "other"
cells = vtk.vtkFloatArray(); cells.SetName("cellsize")
centre = vtk.vtkCellCenters()
for c in range(img.GetNumberOfCells()):
    pts = img.GetCell(c).GetPoints()
    p = [sum(pts.GetPoint(k)[a] for k in range(8)) / 8 for a in range(3)]
    cells.InsertNextValue(f(p))
img.GetCellData().AddArray(cells)

for name, setup in [
    ("vtk_image_appended_raw_zlib.vti", lambda w: (w.SetDataModeToAppended(), w.EncodeAppendedDataOff(), w.SetCompressorTypeToZLib())),
    ("vtk_image_binary_uint32.vti", lambda w: (w.SetDataModeToBinary(), w.SetHeaderTypeToUInt32(), w.SetCompressorTypeToNone())),
    ("vtk_image_ascii.vti", lambda w: (w.SetDataModeToAscii(),)),
]:
    w = vtk.vtkXMLImageDataWriter()
    w.SetInputData(img)
    w.SetFileName(name)
    setup(w)
    assert w.Write() == 1
print(vtk.vtkVersion.GetVTKVersion())
