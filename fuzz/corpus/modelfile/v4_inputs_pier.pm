# by hand: version 4, the columns the aux terms read and the pier side
pm-model 4
mount equatorial
order 0
latitude 0.8
input 1 press
input 0 hum.rel-2
pier west
terms 8
term a 1 0 0 1e-4
term b 2 0 0 -2e-4
term c' 3 0 0 0.001
term d 4 0 0 0
term e' 5 0 0 -0.0005
term i 6 0 0 3.5e-05
xterm e'*aux1 aux 5 0 0 0 4 1010 1e-6
xterm c'*aux0 aux 3 0 0 0 3 55 -2e-7
end
