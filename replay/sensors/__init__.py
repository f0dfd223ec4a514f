"""Sensors: each turns a plant's Scene into a measurement (cameras render images and measure them).

OpenCV is kept to one thread: the sensors process small images and crops, on which its worker
threads cost more than they save (``connectedComponentsWithStats`` on a 14 x 14 crop: 11.5 us of
CPU with 2 threads, 3.8 us with 1, and far more wall time on a busy machine).
"""

import cv2

cv2.setNumThreads(1)
